# zlib (zlib1g-dev, a dependency of libhdf5-dev): the snapshot writer deflates chunks itself, on
# the worker threads, and stores them with H5Dwrite_chunk (src/io/hdf5_writer.cpp).
if(NOT TARGET ZLIB::ZLIB)
  find_package(ZLIB REQUIRED)
endif()
if(TARGET hdf5::hdf5)
  return()
endif()
find_package(HDF5 REQUIRED COMPONENTS C)
