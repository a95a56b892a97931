# Locates the Thrust/CUB headers and provides the INTERFACE IMPORTED target
# sphere::thrust_headers.
#
# This file is used by the sphere build itself and is installed next to
# sphereConfig.cmake, so that an installed copy of sphere finds Thrust the same
# way on the consumer's machine.
#
# Search order (first directory that contains thrust/version.h wins):
#   1. SPHERE_THRUST_INCLUDE_DIR, if set by the user (cache variable)
#   2. ${CUDAToolkit_ROOT}/include/cccl, ${CUDAToolkit_ROOT}/include
#      (CMake variable first, then environment variable)
#   3. the toolkit of the CUDA compiler in use (CMAKE_CUDA_COMPILER), if any
#   4. /usr/local/cuda/include/cccl   (CUDA >= 13 layout)
#   5. /usr/local/cuda/include        (CUDA <= 12 layout)
#   6. /usr/include                   (Debian libthrust-dev / libcub-dev)
#
# Results:
#   SPHERE_THRUST_FOUND         TRUE when the headers were found
#   SPHERE_THRUST_INCLUDE_DIR   the directory that holds thrust/version.h (cache)
#   SPHERE_THRUST_VERSION       e.g. 3.0.1
#   sphere::thrust_headers      INTERFACE IMPORTED target (only when found)

set(_sphere_thrust_candidates "")
foreach(_sphere_root IN ITEMS "${CUDAToolkit_ROOT}" "$ENV{CUDAToolkit_ROOT}")
    if(_sphere_root)
        list(APPEND _sphere_thrust_candidates "${_sphere_root}/include/cccl" "${_sphere_root}/include")
    endif()
endforeach()
if(CMAKE_CUDA_COMPILER)
    # <toolkit>/bin/nvcc -> <toolkit>
    get_filename_component(_sphere_nvcc_bin "${CMAKE_CUDA_COMPILER}" DIRECTORY)
    get_filename_component(_sphere_root "${_sphere_nvcc_bin}" DIRECTORY)
    list(APPEND _sphere_thrust_candidates "${_sphere_root}/include/cccl" "${_sphere_root}/include")
endif()
list(APPEND _sphere_thrust_candidates
    /usr/local/cuda/include/cccl
    /usr/local/cuda/include
    /usr/include)

find_path(SPHERE_THRUST_INCLUDE_DIR
    NAMES thrust/version.h
    PATHS ${_sphere_thrust_candidates}
    NO_DEFAULT_PATH
    DOC "Directory that contains thrust/version.h (and cub/)")

set(SPHERE_THRUST_FOUND FALSE)
set(SPHERE_THRUST_VERSION "")
if(SPHERE_THRUST_INCLUDE_DIR AND EXISTS "${SPHERE_THRUST_INCLUDE_DIR}/thrust/version.h")
    set(SPHERE_THRUST_FOUND TRUE)

    # THRUST_VERSION is MMMmmmpp (>= 2.x) or MMMmmpp (1.x): major = v / 100000.
    file(STRINGS "${SPHERE_THRUST_INCLUDE_DIR}/thrust/version.h" _sphere_thrust_line
         REGEX "^#define[ \t]+THRUST_VERSION[ \t]+[0-9]+")
    if(_sphere_thrust_line MATCHES "THRUST_VERSION[ \t]+([0-9]+)")
        set(_sphere_v "${CMAKE_MATCH_1}")
        math(EXPR _sphere_major "${_sphere_v} / 100000")
        math(EXPR _sphere_minor "(${_sphere_v} / 100) % 1000")
        math(EXPR _sphere_patch "${_sphere_v} % 100")
        set(SPHERE_THRUST_VERSION "${_sphere_major}.${_sphere_minor}.${_sphere_patch}")
    endif()

    # GLOBAL, so that a second find_package(sphere) in a sibling directory
    # reuses it. The file itself has no include guard on purpose: it must set
    # SPHERE_THRUST_FOUND in every scope that includes it.
    if(NOT TARGET sphere::thrust_headers)
        add_library(sphere::thrust_headers INTERFACE IMPORTED GLOBAL)
        # /usr/include is searched anyway; passing it as -isystem would break
        # the #include_next chain of libstdc++.
        if(NOT SPHERE_THRUST_INCLUDE_DIR STREQUAL "/usr/include")
            set_target_properties(sphere::thrust_headers PROPERTIES
                INTERFACE_INCLUDE_DIRECTORIES "${SPHERE_THRUST_INCLUDE_DIR}")
        endif()
        if(NOT SPHERE_THRUST_FIND_QUIETLY)
            message(STATUS "sphere: Thrust ${SPHERE_THRUST_VERSION} headers in ${SPHERE_THRUST_INCLUDE_DIR}")
        endif()
    endif()
endif()

unset(_sphere_thrust_candidates)
unset(_sphere_thrust_line)
unset(_sphere_root)
unset(_sphere_nvcc_bin)
unset(_sphere_v)
unset(_sphere_major)
unset(_sphere_minor)
unset(_sphere_patch)
