if(TARGET assimp::assimp)
  return()
endif()
find_package(assimp REQUIRED)
