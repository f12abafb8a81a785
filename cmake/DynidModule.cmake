# dynid_module(<name> SOURCES ... DEPS ...): the library target dynid_<name> with alias dynid::<name>;
# public headers in <name>/include/dynid/<name>/, sources and internal headers in <name>/src/.
function(dynid_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(dynid_${name} ${ARG_SOURCES})
  add_library(dynid::${name} ALIAS dynid_${name})
  set_target_properties(dynid_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME dynid_${name})
  target_include_directories(dynid_${name}
    PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(dynid_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()
