# ph_add_module(name SOURCES ... HEADERS ... DEPS ... PRIVATE_DEPS ...)
# defines the library pointhaptics_<name> (alias pointhaptics::<name>; the umbrella module is just
# pointhaptics), installs it with its headers and adds it to the exported package
function(ph_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;HEADERS;DEPS;PRIVATE_DEPS" ${ARGN})
  if(name STREQUAL "pointhaptics")
    set(target pointhaptics)
  else()
    set(target pointhaptics_${name})
  endif()
  add_library(${target} ${ARG_SOURCES})
  add_library(pointhaptics::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_link_libraries(${target} PUBLIC ${ARG_DEPS} pointhaptics::build_flags PRIVATE ${ARG_PRIVATE_DEPS})
  foreach(header ${ARG_HEADERS})
    get_filename_component(dir ${header} DIRECTORY)
    install(FILES ${header} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/pointhaptics/${dir})
  endforeach()
  install(TARGETS ${target} EXPORT PointHapticsTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()
