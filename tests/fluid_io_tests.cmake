# Included from tests/CMakeLists.txt (after io_tests.cmake, which defines SPHERE_VTK_PYTHON and
# SPHERE_TEST_ENVIRONMENT is set above): the fluid's VTK ImageData files (include/sphere/io/vti.cuh)
# read back by VTK's own reader, and the fluid examples (settling, permeability) end to end.
#
# - fluid_io_vti_read: vti_writer_for_test (tests/vti_writer_main.cpp) writes known fields in
#   float and double, tests/read_vti.py reads them with vtkXMLImageDataReader and compares
#   every cell value, the origin, spacing, time and the .pvd.
# - example_settling / example_permeability: each example on a small case writes its output
#   folder and must end with its "output in ..." line; example_<name>_vti then reads every fluid
#   frame of it back (FIXTURES: the read-back runs after its example) and checks values the
#   set-up fixes: the prescribed pressures, the hydrostatic pressure at the bottom of the
#   settling column (rho g (nz - 1) cell; the particle adds 0.02 Pa), porosities in (0, 1].
# A Python that cannot import VTK skips the read-backs (exit code 77), as io_vtk_read does.

if(NOT DEFINED SPHERE_VTK_PYTHON)
    set(SPHERE_VTK_PYTHON "/usr/bin/python3" CACHE FILEPATH
        "Python interpreter that can import VTK (Debian python3-vtk9), for the VTK read-back tests")
endif()

add_executable(vti_writer_for_test "${CMAKE_CURRENT_LIST_DIR}/vti_writer_main.cpp")
target_link_libraries(vti_writer_for_test PRIVATE sphere::sphere sphere_project_flags)

if(EXISTS "${SPHERE_VTK_PYTHON}")
    add_test(NAME fluid_io_vti_read
        COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/read_vti.py"
                --writer "$<TARGET_FILE:vti_writer_for_test>"
                "${CMAKE_CURRENT_BINARY_DIR}/vti_read_test")
    set_tests_properties(fluid_io_vti_read PROPERTIES
        SKIP_RETURN_CODE 77
        LABELS io
        TIMEOUT 120)
else()
    add_test(NAME fluid_io_vti_read
        COMMAND "${CMAKE_COMMAND}" -E echo "SKIP: ${SPHERE_VTK_PYTHON} not found; install python3-vtk9")
    set_tests_properties(fluid_io_vti_read PROPERTIES
        SKIP_REGULAR_EXPRESSION "SKIP:"
        LABELS io)
endif()

# Small cases: settling in a 4 x 4 x 10 column for 5 ms (float), permeability on a 4 x 4 x 8 bed
# for at most 20 ms. Their read-back checks (cell ids are VTK's, x fastest):
#   settling: the top layer (cells 144..159) holds p = 0 exactly; the bottom cell 0 the
#     hydrostatic 1000 x 9.81 x 9 x 0.005 = 441.45 Pa within 1e-3; porosity in (0, 1].
#   permeability: the bottom layer p = 8 Pa exactly (cell 0), the top layer 0 (cell 112).
set(_sphere_fluid_example_args_settling --nz 10 --time 0.005 --output-interval 0.0025 --precision float)
set(_sphere_fluid_example_dims_settling 4 4 10)
set(_sphere_fluid_example_checks_settling
    --check pressure 150 0 0 --check pressure 0 441.45 1e-3 --range porosity 1e-6 1)
set(_sphere_fluid_example_args_permeability --nz 8 --time 0.02 --output-interval 0.01)
set(_sphere_fluid_example_dims_permeability 4 4 8)
set(_sphere_fluid_example_checks_permeability
    --check pressure 0 8 0 --check pressure 112 0 0 --range porosity 1e-6 1)

foreach(_example IN ITEMS settling permeability)
    if(NOT TARGET ${_example})
        continue()
    endif()
    set(_out "${CMAKE_CURRENT_BINARY_DIR}/example_${_example}")
    add_test(NAME example_${_example}
        COMMAND ${_example} ${_sphere_fluid_example_args_${_example}} -q -o "${_out}")
    set_tests_properties(example_${_example} PROPERTIES
        LABELS example
        ENVIRONMENT "${SPHERE_TEST_ENVIRONMENT}"
        TIMEOUT 300
        FIXTURES_SETUP example_${_example}_output
        PASS_REGULAR_EXPRESSION "output in .*example_${_example}/: particles.pvd \\([0-9]+ frames?\\), fluid.pvd \\([0-9]+ frames?\\), series.csv \\([0-9]+ rows?\\)")
    add_test(NAME example_${_example}_vti
        COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/read_vti.py"
                --pvd "${_out}/fluid.pvd" --dims ${_sphere_fluid_example_dims_${_example}}
                ${_sphere_fluid_example_checks_${_example}})
    set_tests_properties(example_${_example}_vti PROPERTIES
        LABELS example
        SKIP_RETURN_CODE 77
        FIXTURES_REQUIRED example_${_example}_output)
endforeach()

# Consolidation with pore fluid (examples/fluid_consolidation): 100 particles, 0.1 s of loading
# (a few seconds), with the Darcy model (the default) and with Navier-Stokes. The one regex ('.'
# spans lines in CMake) asks for a positive peak excess pore pressure at the bottom and the
# final "output in ..." line; scripts/plot_series.py then draws terzaghi.csv (the settlement and
# the bottom's excess pressure against Terzaghi's).
if(TARGET fluid_consolidation)
    foreach(_model IN ITEMS darcy navier-stokes)
        set(_name example_fluid_consolidation_${_model})
        add_test(NAME ${_name}
            COMMAND fluid_consolidation -n 100 --time 0.1 --rest 0.005 --output-interval 0.01 --model ${_model}
                    -q -o "${CMAKE_CURRENT_BINARY_DIR}/${_name}")
        set_tests_properties(${_name} PROPERTIES
            LABELS example
            ENVIRONMENT "${SPHERE_TEST_ENVIRONMENT}"
            TIMEOUT 300
            FIXTURES_SETUP ${_name}_output
            PASS_REGULAR_EXPRESSION "peak excess pore pressure at the bottom \\(Pa\\) +[1-9][0-9]*\\.[0-9]+ .*output in .*${_name}/: particles.pvd \\([0-9]+ frames?\\), fluid.pvd \\([0-9]+ frames?\\), series.csv \\([0-9]+ rows?\\), terzaghi.csv \\([1-9][0-9]* rows?\\)")
    endforeach()
    add_test(NAME example_fluid_consolidation_plot
        COMMAND "${SPHERE_VTK_PYTHON}" "${PROJECT_SOURCE_DIR}/scripts/plot_series.py"
                "${CMAKE_CURRENT_BINARY_DIR}/example_fluid_consolidation_darcy/terzaghi.csv")
    set_tests_properties(example_fluid_consolidation_plot PROPERTIES
        LABELS example
        FIXTURES_REQUIRED example_fluid_consolidation_darcy_output
        PASS_REGULAR_EXPRESSION "terzaghi.png")
endif()
