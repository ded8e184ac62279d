# CMake package configuration for the tissuesim C API, installed by cmake/install.sh to
# PREFIX/lib/cmake/tissuesim/. Use:
#
#   find_package(tissuesim 0.1 CONFIG REQUIRED)     # CMAKE_PREFIX_PATH=PREFIX
#   target_link_libraries(app PRIVATE tissuesim::tissuesim)         # shared
#   target_link_libraries(app PRIVATE tissuesim::tissuesim_static)  # static
#
# tissuesim is a Rust library with a C ABI: the static library needs the system libraries
# Rust's standard library uses (pthread, dl, m), which tissuesim::tissuesim_static brings.

get_filename_component(_tissuesim_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

# A prefix without the header or the shared library is not a tissuesim installation: say so
# rather than define a target that fails at link time.
foreach(_tissuesim_file include/tissuesim.h lib/libtissuesim.so)
  if(NOT EXISTS "${_tissuesim_prefix}/${_tissuesim_file}")
    set(tissuesim_FOUND FALSE)
    set(tissuesim_NOT_FOUND_MESSAGE
        "${_tissuesim_prefix}/${_tissuesim_file} is missing (install with cmake/install.sh PREFIX)")
    unset(_tissuesim_file)
    unset(_tissuesim_prefix)
    return()
  endif()
endforeach()
unset(_tissuesim_file)

if(NOT TARGET tissuesim::tissuesim)
  add_library(tissuesim::tissuesim SHARED IMPORTED)
  set_target_properties(tissuesim::tissuesim PROPERTIES
    IMPORTED_LOCATION "${_tissuesim_prefix}/lib/libtissuesim.so"
    IMPORTED_NO_SONAME TRUE
    INTERFACE_INCLUDE_DIRECTORIES "${_tissuesim_prefix}/include"
    INTERFACE_LINK_LIBRARIES "m")
endif()

if(NOT TARGET tissuesim::tissuesim_static AND EXISTS "${_tissuesim_prefix}/lib/libtissuesim.a")
  add_library(tissuesim::tissuesim_static STATIC IMPORTED)
  set_target_properties(tissuesim::tissuesim_static PROPERTIES
    IMPORTED_LOCATION "${_tissuesim_prefix}/lib/libtissuesim.a"
    INTERFACE_INCLUDE_DIRECTORIES "${_tissuesim_prefix}/include"
    INTERFACE_LINK_LIBRARIES "pthread;dl;m")
endif()

set(tissuesim_INCLUDE_DIRS "${_tissuesim_prefix}/include")
set(tissuesim_LIBRARIES tissuesim::tissuesim)
unset(_tissuesim_prefix)
