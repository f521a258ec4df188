# Finds libzip's header and library and defines the imported target simsr_libzip::zip.
# Debian's libzip-config.cmake references the zipcmp/zipmerge/ziptool programs, which live in
# other packages and make find_package(libzip CONFIG) fail when they are absent; the library
# itself needs only these two files.
if(NOT TARGET simsr_libzip::zip)
  find_path(SIMSR_LIBZIP_INCLUDE_DIR zip.h)
  find_library(SIMSR_LIBZIP_LIBRARY NAMES zip)
  if(NOT SIMSR_LIBZIP_INCLUDE_DIR OR NOT SIMSR_LIBZIP_LIBRARY)
    message(FATAL_ERROR "simsr needs libzip for .npz files (Debian: apt-get install libzip-dev)")
  endif()
  add_library(simsr_libzip::zip UNKNOWN IMPORTED)
  set_target_properties(simsr_libzip::zip PROPERTIES
    IMPORTED_LOCATION "${SIMSR_LIBZIP_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${SIMSR_LIBZIP_INCLUDE_DIR}")
endif()
