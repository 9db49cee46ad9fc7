# Installs occull from BUILD_DIR into a scratch prefix, then configures,
# builds and runs tests/consumer and the example engine (examples/engine,
# which implements a Backend and renders frames) against it with
# find_package(occull).
set(prefix "${WORK_DIR}/prefix")
set(consumer_build "${WORK_DIR}/consumer")
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
execute_process(COMMAND "${CMAKE_COMMAND}" -S "${SOURCE_DIR}/tests/consumer" -B "${consumer_build}"
                        -G Ninja -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release ${flags}
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer with find_package(occull) failed: ${rc}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${consumer_build}" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer failed: ${rc}")
endif()
execute_process(COMMAND "${consumer_build}/consumer" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "the consumer failed: ${rc}")
endif()

set(engine_build "${WORK_DIR}/engine")
execute_process(COMMAND "${CMAKE_COMMAND}" -S "${SOURCE_DIR}/examples/engine" -B "${engine_build}"
                        -G Ninja -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release ${flags}
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the example engine with find_package(occull) failed: ${rc}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${engine_build}" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the example engine failed: ${rc}")
endif()
execute_process(COMMAND "${engine_build}/occull_example_engine" --frames 20 --size 96x54 RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "the example engine failed: ${rc}")
endif()
