# Debian's mujoco config lists /usr/include/libqhull_r/, which exists only with libqhull-dev;
# CMake refuses a missing include directory, so keep only the ones that exist. Included after
# find_package(mujoco) by the top-level CMakeLists.txt and tests/.
if(TARGET mujoco::mujoco)
  get_target_property(_mujoco_includes mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
  set(_mujoco_existing_includes)
  foreach(_dir ${_mujoco_includes})
    if(EXISTS "${_dir}")
      list(APPEND _mujoco_existing_includes "${_dir}")
    endif()
  endforeach()
  set_target_properties(mujoco::mujoco PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${_mujoco_existing_includes}")
endif()
