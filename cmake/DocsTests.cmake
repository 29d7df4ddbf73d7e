# The documentation's tests (scripts/check_doc_figures.py,
# scripts/check_doc_commands.py):
#   docs.figures      every figure quoted in the Markdown agrees with its results file,
#                     and no quoted file is older than its bound (commits that touch core)
#   docs.figures_ages the age bound itself, on a scratch git repository (scripts/tests/)
#   docs.side_by_side the benchmark's side-by-side table (scripts/tests/)
#   docs.commands     every command block of README.md and of the component READMEs
#                     (check_doc_commands.py's DEFAULT_FILES) runs as written, in a
#                     scratch copy, or is marked as run elsewhere or not run, with why
#   docs.cpp_example  README.md's C++ example, compiled from the README itself, runs
if(EXISTS /usr/bin/python3)
  set(IDCOL_DOCS_PYTHON /usr/bin/python3)
else()
  find_program(IDCOL_DOCS_PYTHON python3)
endif()
if(NOT IDCOL_DOCS_PYTHON)
  message(STATUS "idcol: no python3, the docs.* tests are left out")
  return()
endif()
add_test(NAME docs.figures COMMAND ${IDCOL_DOCS_PYTHON} ${PROJECT_SOURCE_DIR}/scripts/check_doc_figures.py)
add_test(NAME docs.figures_ages COMMAND ${IDCOL_DOCS_PYTHON} ${PROJECT_SOURCE_DIR}/scripts/tests/check_doc_figures_test.py)
add_test(NAME docs.side_by_side
         COMMAND ${IDCOL_DOCS_PYTHON} ${PROJECT_SOURCE_DIR}/scripts/tests/sim_batch_side_by_side_test.py)
add_test(NAME docs.commands
         COMMAND ${IDCOL_DOCS_PYTHON} ${PROJECT_SOURCE_DIR}/scripts/check_doc_commands.py --build ${PROJECT_BINARY_DIR}
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
# It builds (scripts/run.sh) and runs the README's recipes: minutes.
set_tests_properties(docs.commands PROPERTIES TIMEOUT 2400 LABELS "docs;slow" RUN_SERIAL TRUE)

set(_readme_example ${PROJECT_BINARY_DIR}/docs/readme_example.cpp)
add_custom_command(OUTPUT ${_readme_example}
                   COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/docs
                   COMMAND ${IDCOL_DOCS_PYTHON} ${PROJECT_SOURCE_DIR}/scripts/check_doc_commands.py
                           --extract-cpp ${PROJECT_SOURCE_DIR}/README.md ${_readme_example}
                   DEPENDS ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/scripts/check_doc_commands.py
                   COMMENT "README.md's C++ example")
add_executable(idcol_readme_example ${_readme_example})
target_link_libraries(idcol_readme_example PRIVATE idcol_core)
add_test(NAME docs.cpp_example COMMAND idcol_readme_example)
set_tests_properties(docs.figures docs.figures_ages docs.cpp_example docs.side_by_side PROPERTIES LABELS docs)
