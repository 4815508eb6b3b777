# Bullet 3.24 (Debian libbullet-dev), DOUBLE precision: target surge_bullet.
# CMake's FindBullet module gives the include directory (Debian's BulletConfig.cmake is broken:
# relative include path, missing BulletInverseDynamics; shared notes deps-debian.md P4). FindBullet
# only knows the float libraries, so the *-float64 ones (same package) are looked up beside them
# and BT_USE_DOUBLE_PRECISION is defined to match (btScalar = double, like Real). A mismatch of
# define and libraries fails to link (P5); rigid_world.cpp also static_asserts sizeof(btScalar).
# Included only by src/rigid/rigid_world.cpp (STYLE H.10).
if(TARGET surge_bullet)
  return()
endif()
find_package(Bullet REQUIRED)
get_filename_component(_surge_bullet_libdir "${BULLET_DYNAMICS_LIBRARY}" DIRECTORY)
set(_surge_bullet_libs)
foreach(_lib BulletDynamics BulletCollision LinearMath)
  find_library(SURGE_BULLET_${_lib}_FLOAT64 NAMES ${_lib}-float64 HINTS "${_surge_bullet_libdir}"
               REQUIRED)
  list(APPEND _surge_bullet_libs "${SURGE_BULLET_${_lib}_FLOAT64}")
endforeach()
add_library(surge_bullet INTERFACE)
target_include_directories(surge_bullet SYSTEM INTERFACE ${BULLET_INCLUDE_DIRS})
target_compile_definitions(surge_bullet INTERFACE BT_USE_DOUBLE_PRECISION)
target_link_libraries(surge_bullet INTERFACE ${_surge_bullet_libs})
