# The packaging test (ctest runs it with cmake -P): install the build tree into a temporary
# prefix, configure and build tests/packaging/consumer against it with find_package(extwrench),
# one consumer per target (core, io, app; the consumer's CMakeLists checks that the core links
# Eigen only and io neither Threads nor gnuplot), run them, and check the installed CLI and
# model files.
#
# Inputs: BUILD_DIR, CONSUMER_DIR, WORK_DIR, CXX_COMPILER, SANITIZE (ON when the build uses
# the sanitizers: the consumer must then link their runtimes too), HAVE_CLI (1 when the
# extwrench binary is built), HAVE_MUJOCO (1 when extwrench::mujoco is built: its component is
# then installed and a fourth consumer loads the installed MJCF robot through it).
foreach(var BUILD_DIR CONSUMER_DIR WORK_DIR CXX_COMPILER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_packaging_test.cmake: ${var} is not set")
  endif()
endforeach()

set(prefix ${WORK_DIR}/prefix)
set(consumer_build ${WORK_DIR}/consumer-build)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "packaging test: ${what} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ok\n${out}")
endfunction()

run_step("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

set(expected include/extwrench/dynamics/rnea.hpp include/extwrench/io/csv.hpp
    include/extwrench/app/replay.hpp
    share/extwrench/models/paper_arm.urdf share/extwrench/models/paper_arm.yaml)
if(HAVE_CLI)
  list(APPEND expected bin/extwrench)
endif()
if(HAVE_MUJOCO)
  list(APPEND expected include/extwrench/bridges/mjcf.hpp include/extwrench/bridges/mujoco.hpp
       share/extwrench/models/paper_arm.xml)
else()
  set(HAVE_MUJOCO 0)
endif()
foreach(f ${expected})
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "packaging test: ${f} is not installed")
  endif()
endforeach()
file(GLOB config ${prefix}/lib*/cmake/extwrench/extwrenchConfig.cmake)
if(NOT config)
  message(FATAL_ERROR "packaging test: no extwrenchConfig.cmake under ${prefix}/lib*/cmake/extwrench")
endif()

set(flags "")
if(SANITIZE)
  set(flags -DCMAKE_CXX_FLAGS=-fsanitize=address,undefined
            -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
endif()
run_step("configure the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${consumer_build}
         -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
         -DCMAKE_BUILD_TYPE=Release -DEXTWRENCH_CONSUMER_MUJOCO=${HAVE_MUJOCO} ${flags})
run_step("build the consumer" ${CMAKE_COMMAND} --build ${consumer_build} --parallel 2)
run_step("core-only consumer" ${consumer_build}/core/consumer_core)
# The core as on a machine with Eigen alone: every other dependency's find_package disabled (a
# REQUIRED find_dependency of a disabled package is an error), the core consumer on its own.
set(core_only ${WORK_DIR}/core-only)
file(MAKE_DIRECTORY ${core_only})
file(WRITE ${core_only}/CMakeLists.txt
     "cmake_minimum_required(VERSION 3.22)\nproject(core_only LANGUAGES CXX)\n"
     "add_subdirectory(${CONSUMER_DIR}/core core)\n")
set(disabled "")
foreach(p yaml-cpp tinyxml2 assimp embree Threads mujoco)
  list(APPEND disabled -DCMAKE_DISABLE_FIND_PACKAGE_${p}=ON)
endforeach()
run_step("configure the core consumer with only Eigen findable" ${CMAKE_COMMAND} -S ${core_only}
         -B ${core_only}/build -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
         -DCMAKE_BUILD_TYPE=Release ${flags} ${disabled})
run_step("build the core consumer with only Eigen findable" ${CMAKE_COMMAND} --build
         ${core_only}/build)
# The core consumer with a controller's own flags, against the same library: -march=native (Eigen
# aligns to 32 bytes with AVX) and, when the library is not sanitized, AddressSanitizer (Eigen
# then allocates through its own scheme). Both crashed on the library's objects.
set(flag_sets "-march=native")
if(NOT SANITIZE)
  list(APPEND flag_sets "-fsanitize=address")
endif()
set(k 0)
foreach(extra ${flag_sets})
  math(EXPR k "${k} + 1")
  set(flagged ${WORK_DIR}/core-flags-${k})
  file(MAKE_DIRECTORY ${flagged})
  file(WRITE ${flagged}/CMakeLists.txt
       "cmake_minimum_required(VERSION 3.22)\nproject(core_flags LANGUAGES CXX)\n"
       "add_subdirectory(${CONSUMER_DIR}/core core)\n")
  set(cxx_flags ${extra})
  set(link_flags "")
  if(SANITIZE)
    string(APPEND cxx_flags " -fsanitize=address,undefined")
    set(link_flags -fsanitize=address,undefined)
  elseif(extra MATCHES "sanitize")
    set(link_flags ${extra})
  endif()
  run_step("configure the core consumer with ${extra}" ${CMAKE_COMMAND} -S ${flagged}
           -B ${flagged}/build -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
           -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS=${cxx_flags}"
           "-DCMAKE_EXE_LINKER_FLAGS=${link_flags}")
  run_step("build the core consumer with ${extra}" ${CMAKE_COMMAND} --build ${flagged}/build)
  run_step("core consumer built with ${extra}" ${flagged}/build/core/consumer_core)
endforeach()
run_step("io consumer on the installed URDF" ${consumer_build}/io/consumer_io ${prefix}/share/extwrench/models/paper_arm.urdf)
run_step("io consumer on the installed DH table" ${consumer_build}/io/consumer_io ${prefix}/share/extwrench/models/paper_arm.yaml)
run_step("app consumer (replay_log)" ${consumer_build}/app/consumer_app ${prefix}/share/extwrench/models/paper_arm.urdf ${WORK_DIR}/app_out)
if(HAVE_MUJOCO)
  run_step("mujoco consumer on the installed MJCF" ${consumer_build}/mujoco/consumer_mujoco ${prefix}/share/extwrench/models/paper_arm.xml)
endif()
if(HAVE_CLI)
  run_step("installed CLI" ${prefix}/bin/extwrench info ${prefix}/share/extwrench/models/paper_arm.yaml)
endif()
file(REMOVE_RECURSE ${WORK_DIR})
