if(TARGET yaml-cpp)
  return()
endif()
find_package(yaml-cpp REQUIRED)
