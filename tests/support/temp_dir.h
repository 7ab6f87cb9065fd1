// A fresh folder per test under the system's temporary directory, removed with its contents:
// tests never write into the working directory.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace pine::test {

class TempDir {
public:
    explicit TempDir(const std::string& prefix = "pine-test")
    {
        std::string pattern =
            (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
        if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
        mPath = pattern;
    }
    ~TempDir()
    {
        std::error_code ec;
        std::filesystem::remove_all(mPath, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return mPath; }

    /// Writes `text` to `name` in the folder and returns its path.
    std::filesystem::path write(const std::string& name, const std::string& text) const
    {
        const std::filesystem::path p = mPath / name;
        std::ofstream(p) << text;
        return p;
    }

private:
    std::filesystem::path mPath;
};

}  // namespace pine::test
