# Every dependency comes from Debian 12 packages (scripts/install-deps.sh installs them).
# Pitfalls of those packages are handled here, once (see shared DESIGN.md).

# Ask for CONFIG packages explicitly: OpenVDB's module folder, added below, carries its own
# FindTBB and FindOpenEXR that would otherwise take over.
find_package(glm CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(OpenEXR CONFIG REQUIRED)
find_package(OpenImageIO CONFIG REQUIRED)
# Embree 3 (libembree-dev) exports the imported target `embree`: the BVH of the geometry method.
find_package(embree 3 CONFIG REQUIRED)

# OpenImageIO's exported target names /usr/include/opencv4, which Debian does not install
# with it: drop that directory from the target.
foreach(prop INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
  get_target_property(_dirs OpenImageIO::OpenImageIO ${prop})
  if(_dirs)
    list(FILTER _dirs EXCLUDE REGEX "opencv4")
    set_target_properties(OpenImageIO::OpenImageIO PROPERTIES ${prop} "${_dirs}")
  endif()
endforeach()

# OpenVDB 10.0.1 ships a find-module, not a config package; it needs boost-iostreams and sets
# BUILD_SHARED_LIBS in our scope, so keep our value.
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
set(_pine_shared ${BUILD_SHARED_LIBS})
find_package(OpenVDB REQUIRED)
set(BUILD_SHARED_LIBS ${_pine_shared})

if(PINE_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(PINE_BUILD_BENCHMARKS)
  find_package(benchmark CONFIG REQUIRED)
endif()
