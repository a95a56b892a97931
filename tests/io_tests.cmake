# Included from tests/CMakeLists.txt: the VTK read-back test. vtk_writer_for_test
# (tests/vtk_writer_main.cpp) writes .vtu frames, a .pvd collection and the expected values
# (expected.json) into a scratch folder; tests/vtk_read.py reads them back with VTK's own XML
# reader and compares. VTK's Python module comes from Debian's python3-vtk9 (installed by
# scripts/install-deps.sh), which only the system interpreter /usr/bin/python3 can import.
# The test is skipped (exit code 77) only when that interpreter cannot import VTK.

add_executable(vtk_writer_for_test "${CMAKE_CURRENT_LIST_DIR}/vtk_writer_main.cpp")
target_link_libraries(vtk_writer_for_test PRIVATE sphere::sphere sphere_project_flags)

set(SPHERE_VTK_PYTHON "/usr/bin/python3" CACHE FILEPATH
    "Python interpreter that can import VTK (Debian python3-vtk9), for the VTK read-back test")

if(EXISTS "${SPHERE_VTK_PYTHON}")
    add_test(NAME io_vtk_read
        COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/vtk_read.py"
                --writer "$<TARGET_FILE:vtk_writer_for_test>"
                "${CMAKE_CURRENT_BINARY_DIR}/vtk_read_test")
    set_tests_properties(io_vtk_read PROPERTIES
        SKIP_RETURN_CODE 77
        LABELS io
        TIMEOUT 120)
else()
    # No interpreter at all: the same as one that cannot import VTK.
    add_test(NAME io_vtk_read
        COMMAND "${CMAKE_COMMAND}" -E echo "SKIP: ${SPHERE_VTK_PYTHON} not found; install python3-vtk9")
    set_tests_properties(io_vtk_read PROPERTIES
        SKIP_REGULAR_EXPRESSION "SKIP:"
        LABELS io)
endif()
