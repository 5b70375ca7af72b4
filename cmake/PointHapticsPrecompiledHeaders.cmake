# Precompiled headers (PH_PRECOMPILED_HEADERS, on by default): Eigen and the standard headers that nearly every
# file includes are parsed once into a precompiled header that every library module reuses, and once more with
# GoogleTest for the test programs. Each is built by a small object library of its own (REUSE_FROM needs a
# target that owns it) with the same flags as its users; a header that GCC finds unusable (other flags) is
# ignored and the text is parsed instead, so a mismatch costs time, never correctness (-Winvalid-pch says so).
option(PH_PRECOMPILED_HEADERS "Precompile Eigen and the common standard headers" ON)

# ph_precompiled_headers_target(name header [LIBS ...]): an object library owning the precompiled `header`
function(ph_precompiled_headers_target name header)
  cmake_parse_arguments(ARG "" "" "LIBS" ${ARGN})
  set(source ${CMAKE_CURRENT_BINARY_DIR}/${name}.cpp)
  file(CONFIGURE OUTPUT ${source} CONTENT "// owns the precompiled header ${header}\n")
  add_library(${name} OBJECT ${source})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  target_compile_features(${name} PRIVATE cxx_std_20)
  target_link_libraries(${name} PRIVATE pointhaptics_build_flags ${ARG_LIBS})
  target_precompile_headers(${name} PRIVATE ${PROJECT_SOURCE_DIR}/cmake/pch/${header})
endfunction()

# ph_use_precompiled_headers(target from): `target` compiles with the header that `from` precompiled
function(ph_use_precompiled_headers target from)
  if(PH_PRECOMPILED_HEADERS AND TARGET ${from})
    target_precompile_headers(${target} REUSE_FROM ${from})
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Winvalid-pch>)
  endif()
endfunction()

if(PH_PRECOMPILED_HEADERS)
  ph_precompiled_headers_target(pointhaptics_library_pch library_pch.hpp LIBS Eigen3::Eigen)
  # the same for executables (the command line): GCC refuses a header precompiled with -fPIC in a -fPIE
  # compilation, so these are built without either (Debian's GCC makes position-independent executables anyway)
  ph_precompiled_headers_target(pointhaptics_executable_pch library_pch.hpp LIBS Eigen3::Eigen)
  set_target_properties(pointhaptics_executable_pch PROPERTIES POSITION_INDEPENDENT_CODE OFF)
endif()
