# Installs occull from BUILD_DIR into a scratch prefix, then configures,
# builds and runs projects against it with find_package(occull):
#   PART=all   tests/consumer and the example engine (examples/engine, which
#              implements a Backend and renders frames);
#   PART=core  tests/core_consumer, an engine's project that takes the culling
#              core only, configured with the lab's dependencies out of reach;
#              its binary must link none of their libraries (readelf -d).
set(prefix "${WORK_DIR}/prefix")
file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed: ${rc}")
endif()
# A sanitized occull is a static library that needs the sanitizer runtime.
set(flags "")
if(SANITIZE)
  set(flags "-DCMAKE_CXX_FLAGS=-fsanitize=address,undefined" "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined")
endif()
# Configures, builds and runs the project in SOURCE_DIR/FOLDER against the
# installed package; WHAT names it in failures, ARGN are its arguments.
# CONFIGURE_ARGS, when set, go to its configuration.
function(build_and_run what folder program)
  set(build "${WORK_DIR}/${program}")
  execute_process(COMMAND "${CMAKE_COMMAND}" -S "${SOURCE_DIR}/${folder}" -B "${build}"
                          -G Ninja -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release ${flags}
                          ${CONFIGURE_ARGS}
                  RESULT_VARIABLE rc)
  if(rc)
    message(FATAL_ERROR "configuring ${what} with find_package(occull) failed: ${rc}")
  endif()
  execute_process(COMMAND "${CMAKE_COMMAND}" --build "${build}" RESULT_VARIABLE rc)
  if(rc)
    message(FATAL_ERROR "building ${what} failed: ${rc}")
  endif()
  execute_process(COMMAND "${build}/${program}" ${ARGN} RESULT_VARIABLE rc)
  if(rc)
    message(FATAL_ERROR "${what} failed: ${rc}")
  endif()
endfunction()

if(PART STREQUAL "core")
  set(CONFIGURE_ARGS -DCMAKE_DISABLE_FIND_PACKAGE_assimp=ON -DCMAKE_DISABLE_FIND_PACKAGE_OpenGL=ON
                     -DCMAKE_DISABLE_FIND_PACKAGE_fmt=ON -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON)
  build_and_run("the core consumer" tests/core_consumer core_consumer)
  execute_process(COMMAND readelf -d "${WORK_DIR}/core_consumer/core_consumer"
                  OUTPUT_VARIABLE dynamic RESULT_VARIABLE rc)
  if(rc)
    message(FATAL_ERROR "readelf -d core_consumer failed: ${rc}")
  endif()
  string(REGEX MATCHALL "Shared library: \\[[^]]*\\]" needed "${dynamic}")
  message(STATUS "core consumer needs: ${needed}")
  if(NOT needed)
    message(FATAL_ERROR "readelf -d listed no shared library of core_consumer: the check would pass on anything")
  endif()
  foreach(library libassimp libminizip libEGL libGL libOpenGL libfmt libosg)
    if(needed MATCHES "\\[${library}[.-]")
      message(FATAL_ERROR "core_consumer links ${library}: the culling core must not need it\n${needed}")
    endif()
  endforeach()
else()
  foreach(header osg/osg_bench.hpp osg/scene_graph.hpp)  # their code is not installed
    if(EXISTS "${prefix}/include/occull/${header}")
      message(FATAL_ERROR "occull/${header} is installed, but the code it declares is not")
    endif()
  endforeach()
  if(NOT EXISTS "${prefix}/include/occull/osg/culling_group.hpp")
    message(FATAL_ERROR "occull/osg/culling_group.hpp is not installed: the header check above looks in the wrong place")
  endif()
  build_and_run("the consumer" tests/consumer consumer)
  build_and_run("the example engine" examples/engine occull_example_engine --frames 20 --size 96x54)
  # The Vulkan example, where the vk component was built and installed (not under the
  # sanitizers: see tests/CMakeLists.txt, the Vulkan example engine).
  if(EXISTS "${prefix}/lib/cmake/occull/occull-vk-targets.cmake" AND NOT SANITIZE)
    build_and_run("the Vulkan example engine" examples/vk_engine occull_example_vk_engine --frames 20 --size 96x54)
  endif()
endif()
