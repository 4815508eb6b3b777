if(TARGET TBB::tbb)
  return()
endif()
find_package(TBB REQUIRED)
