# Included from tests/CMakeLists.txt, after io_tests.cmake: the PNG read-back test.
# png_writer_for_test (tests/png_writer_main.cpp) renders three spheres into a PNG file and
# their raw pixels beside it; tests/png_read.py reads the PNG file with Pillow and compares.
# Pillow comes from Debian's python3-pil (installed by scripts/install-deps.sh), which only the
# system interpreter SPHERE_VTK_PYTHON (/usr/bin/python3, io_tests.cmake) can import. The test
# is skipped (exit code 77) when that interpreter cannot import Pillow.

add_executable(png_writer_for_test "${CMAKE_CURRENT_LIST_DIR}/png_writer_main.cpp")
target_link_libraries(png_writer_for_test PRIVATE sphere::png sphere_project_flags)

add_test(NAME io_png_read
    COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/png_read.py"
            --writer "$<TARGET_FILE:png_writer_for_test>"
            "${CMAKE_CURRENT_BINARY_DIR}/png_read_test")
set_tests_properties(io_png_read PROPERTIES
    SKIP_RETURN_CODE 77
    LABELS io
    TIMEOUT 120)
