# Included from tests/CMakeLists.txt: the tests of the Python package sphere (python/,
# docs/python.md). Each tests/python/test_*.py is one test, python_<name>, run by
# `${SPHERE_PYTHON} -m pytest` (Debian's python3-pytest, for /usr/bin/python3) with the build's
# package folder on PYTHONPATH and one OpenMP thread, like the C++ tests. The comparisons with
# the C++ examples (test_checkpoint.py, test_consolidation.py, test_shear.py,
# test_experiments.py) run them from SPHERE_CONSOLIDATION, SPHERE_SHEAR, SPHERE_UNIAXIAL and
# SPHERE_TRIAXIAL, test_program.py the sphere program from SPHERE_PROGRAM
# (the package's run_program finds it there too); without them those tests are skipped. test_pip_install.py builds the
# package again with pip: label slow. Nothing is registered when the package is not built
# (SPHERE_BUILD_PYTHON OFF).

if(NOT TARGET sphere_python)
    return()
endif()

set(_sphere_python_environment
    "PYTHONPATH=${PROJECT_BINARY_DIR}/python"
    "SPHERE_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    ${SPHERE_TEST_ENVIRONMENT})
# The C++ examples the experiments are compared with: SPHERE_CONSOLIDATION, SPHERE_SHEAR, ...
foreach(_example IN ITEMS consolidation shear uniaxial triaxial)
    if(TARGET ${_example})
        string(TOUPPER "${_example}" _variable)
        list(APPEND _sphere_python_environment "SPHERE_${_variable}=$<TARGET_FILE:${_example}>")
    endif()
endforeach()
if(TARGET sphere_program)
    list(APPEND _sphere_python_environment "SPHERE_PROGRAM=$<TARGET_FILE:sphere_program>")
endif()

file(GLOB _sphere_python_tests CONFIGURE_DEPENDS "${CMAKE_CURRENT_LIST_DIR}/python/test_*.py")
list(SORT _sphere_python_tests)
foreach(_file IN LISTS _sphere_python_tests)
    get_filename_component(_name "${_file}" NAME_WE)
    string(REGEX REPLACE "^test_" "python_" _name "${_name}")
    # -p no:cacheprovider: pytest writes no .pytest_cache into the source tree.
    add_test(NAME ${_name}
        COMMAND "${SPHERE_PYTHON}" -m pytest -q -p no:cacheprovider "${_file}"
        WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}")
    set_tests_properties(${_name} PROPERTIES
        LABELS python
        ENVIRONMENT "${_sphere_python_environment}"
        TIMEOUT 300)
endforeach()
if(TEST python_pip_install)
    set_tests_properties(python_pip_install PROPERTIES LABELS "python;slow" TIMEOUT 1800)
endif()
