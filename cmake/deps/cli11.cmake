if(TARGET CLI11::CLI11)
  return()
endif()
find_package(CLI11 REQUIRED)
