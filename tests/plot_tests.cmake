# Included from tests/CMakeLists.txt, after io_tests.cmake: the test of scripts/plot_series.py.
# tests/test_plot_series.py writes synthetic CSV series, runs the script on them and checks the
# PNG figures it writes and its error messages. matplotlib and numpy come from Debian's
# python3-matplotlib and python3-numpy (installed by scripts/install-deps.sh), which only the
# system interpreter /usr/bin/python3 can import.
#
# The interpreter is the one io_tests.cmake already names, SPHERE_VTK_PYTHON (a cache variable,
# /usr/bin/python3 by default): no second look-up here. Unlike the VTK test, this one is not
# skipped when the interpreter or its modules are missing: configuring stops with an error.

if(NOT DEFINED SPHERE_VTK_PYTHON)
    message(FATAL_ERROR "tests/plot_tests.cmake: SPHERE_VTK_PYTHON is not set; "
                        "include io_tests.cmake before plot_tests.cmake")
endif()

if(NOT EXISTS "${SPHERE_VTK_PYTHON}")
    message(FATAL_ERROR "The plot_series test needs ${SPHERE_VTK_PYTHON} with matplotlib and numpy, "
                        "but ${SPHERE_VTK_PYTHON} does not exist. Run scripts/install-deps.sh "
                        "(or set SPHERE_VTK_PYTHON to the system Python 3).")
endif()

execute_process(
    COMMAND "${SPHERE_VTK_PYTHON}" -c "import matplotlib, numpy"
    RESULT_VARIABLE _sphere_plot_modules_result
    OUTPUT_QUIET
    ERROR_VARIABLE _sphere_plot_modules_error)
if(NOT _sphere_plot_modules_result EQUAL 0)
    message(FATAL_ERROR "The plot_series test needs matplotlib and numpy, which ${SPHERE_VTK_PYTHON} "
                        "cannot import:\n${_sphere_plot_modules_error}\n"
                        "Run scripts/install-deps.sh (Debian packages python3-matplotlib, python3-numpy).")
endif()

add_test(NAME plot_series
    COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/test_plot_series.py"
            "${PROJECT_SOURCE_DIR}/scripts/plot_series.py")
set_tests_properties(plot_series PROPERTIES
    LABELS plot
    TIMEOUT 120)

# scripts/plot_bond_rose.py: the bonds' rose from a bonds VTK file (tests/test_plot_bond_rose.py
# writes such files, checks the angles, the figure and the errors).
add_test(NAME plot_bond_rose
    COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/test_plot_bond_rose.py"
            "${PROJECT_SOURCE_DIR}/scripts/plot_bond_rose.py")
set_tests_properties(plot_bond_rose PROPERTIES
    LABELS plot
    TIMEOUT 120)
