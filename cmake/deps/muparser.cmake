# muParser (libmuparser-dev): arithmetic in scene files, `${...}` values over `parameters:`.
if(TARGET muparser::muparser)
  return()
endif()
find_package(muparser REQUIRED)
