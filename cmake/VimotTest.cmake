# vimot_add_test(NAME <name> SOURCES <files...> LIBS <targets...> [LABELS <labels...>] [DATA])
# One Catch2 executable per test source group, registered with ctest.
# LABELS: ctest labels, e.g. `slow` for the long simulation tests, so that
#   `ctest -LE slow` is a quick run.
# DATA: the source has test cases tagged [data] that need the shared data
#   (env VIMOT_DATA_DIR, tests/data_dir.h). They run as a second ctest test
#   <name>_data, reported as skipped when they print "VIMOT_SKIP" (the data is
#   absent); <name> runs the other cases, so a skip never hides their result.
function(vimot_add_test)
  cmake_parse_arguments(T "DATA" "NAME" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE vimot_catch_main ${T_LIBS})
  set(tests ${T_NAME})
  if(T_DATA)
    add_test(NAME ${T_NAME} COMMAND ${T_NAME} "~[data]")
    add_test(NAME ${T_NAME}_data COMMAND ${T_NAME} "[data]")
    set_tests_properties(${T_NAME}_data PROPERTIES SKIP_REGULAR_EXPRESSION "VIMOT_SKIP")
    list(APPEND tests ${T_NAME}_data)
  else()
    add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  endif()
  if(T_LABELS)
    set_tests_properties(${tests} PROPERTIES LABELS "${T_LABELS}")
  endif()
endfunction()
