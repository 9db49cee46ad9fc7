# Installs occull from BUILD_DIR into a scratch prefix, then configures,
# builds and runs tests/consumer and the example engine (examples/engine,
# which implements a Backend and renders frames) against it with
# find_package(occull).
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
function(build_and_run what folder program)
  set(build "${WORK_DIR}/${program}")
  execute_process(COMMAND "${CMAKE_COMMAND}" -S "${SOURCE_DIR}/${folder}" -B "${build}"
                          -G Ninja -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release ${flags}
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

build_and_run("the consumer" tests/consumer consumer)
build_and_run("the example engine" examples/engine occull_example_engine --frames 20 --size 96x54)
