#include "pine/support/plot_script.h"

#include <spawn.h>
#include <sys/wait.h>

#include <cstdlib>
#include <string>
#include <vector>

extern char** environ;

namespace pine::tool {

std::filesystem::path plotScript(const std::string& name)
{
    if (const char* env = std::getenv("PINE_PLOT_SCRIPT")) return env;
    // Installed (cmake --install): beside the executable's bin/, in share/pine/.
    std::error_code error;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
    if (!error) {
        const std::filesystem::path installed =
            self.parent_path().parent_path() / PINE_INSTALL_DATADIR / name;
        if (std::filesystem::is_regular_file(installed, error)) return installed;
    }
    return std::filesystem::path(PINE_SOURCE_DIR) / "scripts" / name;
}

bool runPlotScript(const std::filesystem::path& script, const std::filesystem::path& folder)
{
    std::string python = "/usr/bin/python3", path = script.string(), dir = folder.string();
    std::vector<std::string> env;
    for (char** e = environ; *e; ++e) {
        if (std::string(*e).rfind("MPLBACKEND=", 0) != 0) env.emplace_back(*e);
    }
    env.emplace_back("MPLBACKEND=Agg");
    std::vector<char*> envp;
    for (std::string& e : env) envp.push_back(e.data());
    envp.push_back(nullptr);
    char* argv[] = {python.data(), path.data(), dir.data(), nullptr};
    pid_t pid;
    if (::posix_spawn(&pid, python.c_str(), nullptr, nullptr, argv, envp.data()) != 0) {
        return false;
    }
    int status = 0;
    if (::waitpid(pid, &status, 0) != pid) return false;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace pine::tool
