# Included from tests/CMakeLists.txt: the `sphere` program (apps/) end to end
# (tests/test_program.py): a run killed with SIGKILL and resumed equals an uninterrupted one byte
# for byte, --dry, --version and bad input. Its input is the consolidation example's checkpoint
# (the example_consolidation test's output, a fixture).

if(NOT TARGET sphere_program OR NOT TARGET consolidation)
    return()
endif()

add_test(NAME program_sphere
    COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/test_program.py" $<TARGET_FILE:sphere_program>
            "${CMAKE_CURRENT_BINARY_DIR}/example_consolidation/checkpoint.ck"
            "${CMAKE_CURRENT_BINARY_DIR}/program_sphere")
set_tests_properties(program_sphere PROPERTIES
    LABELS example
    ENVIRONMENT "${SPHERE_TEST_ENVIRONMENT}"
    FIXTURES_REQUIRED example_consolidation_output
    PASS_REGULAR_EXPRESSION "all checks passed"
    TIMEOUT 600)

# The CUDA build of the program (sphere-cuda): the same checks on its host backend, and its
# --backend cuda (refused before writing anything without a device; resumed byte for byte with one).
if(TARGET sphere_program_cuda)
    add_test(NAME program_sphere_cuda
        COMMAND "${SPHERE_VTK_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/test_program.py" $<TARGET_FILE:sphere_program_cuda>
                "${CMAKE_CURRENT_BINARY_DIR}/example_consolidation/checkpoint.ck"
                "${CMAKE_CURRENT_BINARY_DIR}/program_sphere_cuda")
    set_tests_properties(program_sphere_cuda PROPERTIES
        LABELS "example;cuda"
        ENVIRONMENT "${SPHERE_TEST_ENVIRONMENT}"
        FIXTURES_REQUIRED example_consolidation_output
        PASS_REGULAR_EXPRESSION "all checks passed"
        TIMEOUT 600)
endif()
