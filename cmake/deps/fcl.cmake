# FCL 0.7 (Debian libfcl-dev): config package, plain target "fcl" (brings ccd, Eigen, octomap).
# Included only by src/contact/mesh_distance.cpp (STYLE H.10).
if(TARGET fcl)
  return()
endif()
find_package(fcl 0.7 REQUIRED)
