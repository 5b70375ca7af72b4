# SuiteSparse's CHOLMOD as an imported target. Debian 12's SuiteSparse 5.12 ships no CMake package for
# it, so it is found by hand. Used by the build and by the installed package's config.
if(NOT TARGET PointHaptics_cholmod)
  find_library(PH_CHOLMOD_LIBRARY cholmod REQUIRED)
  find_library(PH_SUITESPARSECONFIG_LIBRARY suitesparseconfig REQUIRED)
  find_path(PH_CHOLMOD_INCLUDE cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
  add_library(PointHaptics_cholmod UNKNOWN IMPORTED)
  set_target_properties(PointHaptics_cholmod PROPERTIES IMPORTED_LOCATION ${PH_CHOLMOD_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${PH_CHOLMOD_INCLUDE} INTERFACE_LINK_LIBRARIES ${PH_SUITESPARSECONFIG_LIBRARY})
endif()
