# Debian ships only a Find module, in a directory CMake does not search (deps-debian.md P2).
if(TARGET OpenVDB::openvdb)
  return()
endif()
list(APPEND CMAKE_MODULE_PATH "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB")
find_package(OpenVDB REQUIRED)
