// The error a user's input causes (a malformed scene, a missing or damaged file, an output that
// cannot be written): tools print its one line and exit with status 2 (tool_main.h). Each
// component's own error (SceneError, BakeError, ImageError) is one.
#pragma once

#include <stdexcept>

namespace pine {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace pine
