# Warnings as a usage requirement, not global flags: link pine::warnings PRIVATE.
add_library(pine_warnings INTERFACE)
add_library(pine::warnings ALIAS pine_warnings)
target_compile_options(pine_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion>)
target_compile_features(pine_warnings INTERFACE cxx_std_20)
