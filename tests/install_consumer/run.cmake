# Driver of the CTest test "install_consumer" (see tests/CMakeLists.txt):
#   1. cmake --install <build dir> --prefix <SPHERE_INSTALL_PREFIX>
#   2. configure and build tests/install_consumer against that prefix only
#   3. run the consumer and check what it prints
#
# Variables: SPHERE_BUILD_DIR, SPHERE_INSTALL_PREFIX, CONSUMER_SOURCE_DIR,
# CONSUMER_BINARY_DIR, CONFIG, GENERATOR, MAKE_PROGRAM, CXX_COMPILER,
# CUDA_TOOLKIT_ROOT (the last five optional).
cmake_minimum_required(VERSION 3.25)

foreach(_var IN ITEMS SPHERE_BUILD_DIR SPHERE_INSTALL_PREFIX CONSUMER_SOURCE_DIR CONSUMER_BINARY_DIR)
    if(NOT ${_var})
        message(FATAL_ERROR "run.cmake: ${_var} is not set")
    endif()
endforeach()
if(NOT CONFIG)
    set(CONFIG Release)
endif()

function(run_step what)
    message(STATUS "install_consumer: ${what}")
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE _rc)
    if(NOT _rc EQUAL 0)
        message(FATAL_ERROR "install_consumer: ${what} failed (${_rc})")
    endif()
endfunction()

# Start from scratch, so that nothing of a previous run is reused.
file(REMOVE_RECURSE "${SPHERE_INSTALL_PREFIX}" "${CONSUMER_BINARY_DIR}")

# A DESTDIR from the environment would install somewhere else.
run_step("install into ${SPHERE_INSTALL_PREFIX}"
    "${CMAKE_COMMAND}" -E env --unset=DESTDIR
    "${CMAKE_COMMAND}" --install "${SPHERE_BUILD_DIR}" --config "${CONFIG}" --prefix "${SPHERE_INSTALL_PREFIX}")

set(_configure_args
    -S "${CONSUMER_SOURCE_DIR}"
    -B "${CONSUMER_BINARY_DIR}"
    "-DCMAKE_BUILD_TYPE=${CONFIG}"
    "-DCMAKE_PREFIX_PATH=${SPHERE_INSTALL_PREFIX}"
    # Only the scratch prefix may provide sphere.
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF)
if(GENERATOR)
    list(APPEND _configure_args -G "${GENERATOR}")
endif()
if(MAKE_PROGRAM)
    list(APPEND _configure_args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(CXX_COMPILER)
    list(APPEND _configure_args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
endif()
if(CUDA_TOOLKIT_ROOT)
    list(APPEND _configure_args "-DCUDAToolkit_ROOT=${CUDA_TOOLKIT_ROOT}")
endif()
run_step("configure the consumer" "${CMAKE_COMMAND}" ${_configure_args})
run_step("build the consumer" "${CMAKE_COMMAND}" --build "${CONSUMER_BINARY_DIR}" --config "${CONFIG}")

# Single-config generators put the binary at the top, multi-config ones in <CONFIG>/.
set(_exe "")
foreach(_candidate IN ITEMS "${CONSUMER_BINARY_DIR}/consumer" "${CONSUMER_BINARY_DIR}/${CONFIG}/consumer"
                            "${CONSUMER_BINARY_DIR}/consumer.exe" "${CONSUMER_BINARY_DIR}/${CONFIG}/consumer.exe")
    if(NOT _exe AND EXISTS "${_candidate}")
        set(_exe "${_candidate}")
    endif()
endforeach()
if(NOT _exe)
    message(FATAL_ERROR "install_consumer: the consumer executable was not built")
endif()

execute_process(COMMAND "${_exe}" RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
message(STATUS "install_consumer: consumer printed: ${_out}${_err}")
if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "install_consumer: the consumer exited with ${_rc}")
endif()
if(NOT _out MATCHES "sphere consumer: 1 2 3")
    message(FATAL_ERROR "install_consumer: unexpected output from the consumer")
endif()
message(STATUS "install_consumer: OK")
