# vimot_add_test(NAME <name> SOURCES <files...> LIBS <targets...>)
# One Catch2 executable per test source group, registered with ctest.
function(vimot_add_test)
  cmake_parse_arguments(T "" "NAME" "SOURCES;LIBS" ${ARGN})
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE vimot_catch_main ${T_LIBS})
  add_test(NAME ${T_NAME} COMMAND ${T_NAME})
endfunction()
