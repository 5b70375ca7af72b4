# The medical-image libraries as imported targets. Debian 12's NIFTIConfig.cmake points at /usr/lib
# instead of the multiarch folder (its targets fail to import) and teem's TeemConfig.cmake defines no
# target, so both are found by hand. Used by the build and by the installed package's config.
if(NOT TARGET PointHaptics_nifti2)
  find_library(PH_NIFTI2_LIBRARY nifti2 REQUIRED)
  find_library(PH_ZNZ_LIBRARY znz REQUIRED)
  find_path(PH_NIFTI_INCLUDE nifti/nifti2_io.h REQUIRED)
  find_package(ZLIB REQUIRED)
  add_library(PointHaptics_nifti2 UNKNOWN IMPORTED)
  set_target_properties(PointHaptics_nifti2 PROPERTIES IMPORTED_LOCATION ${PH_NIFTI2_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES "${PH_NIFTI_INCLUDE};${PH_NIFTI_INCLUDE}/nifti" INTERFACE_LINK_LIBRARIES "${PH_ZNZ_LIBRARY};ZLIB::ZLIB;m")
endif()
if(NOT TARGET PointHaptics_teem)
  find_library(PH_TEEM_LIBRARY teem REQUIRED)
  find_path(PH_TEEM_INCLUDE teem/nrrd.h REQUIRED)
  add_library(PointHaptics_teem UNKNOWN IMPORTED)
  set_target_properties(PointHaptics_teem PROPERTIES IMPORTED_LOCATION ${PH_TEEM_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${PH_TEEM_INCLUDE})
endif()
