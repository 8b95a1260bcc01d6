# Sanitizer and fuzzing builds: flags applied to every target of the build, so that our
# libraries, programs and tests are all instrumented (the Debian libraries we link are not).
#
#   -DCOHAPTIC_SANITIZE=address,undefined   ASan + UBSan (make test-asan)
#   -DCOHAPTIC_SANITIZE=thread              ThreadSanitizer (make test-tsan)
#   -DCOHAPTIC_FUZZ=ON                      libFuzzer targets (clang only, make fuzz): ASan +
#                                           UBSan with coverage instrumentation everywhere,
#                                           the fuzzer's main linked into the targets only
# Undefined behaviour is fatal (no recovery), so a test or a fuzz run fails on the first
# report instead of printing it and passing. float-cast-overflow is named because GCC's
# "undefined" leaves it out; floating-point division by zero is not checked: the numerics
# rely on IEEE infinities. Include this before the subdirectories.
set(COHAPTIC_SANITIZE "" CACHE STRING "Sanitizers for every target: address,undefined or thread (empty: none)")
option(COHAPTIC_FUZZ "Build the libFuzzer targets (needs clang), with ASan and UBSan" OFF)

if(COHAPTIC_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "COHAPTIC_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++")
  endif()
  if(COHAPTIC_SANITIZE STREQUAL "")
    set(COHAPTIC_SANITIZE address,undefined CACHE STRING "" FORCE)
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

if(NOT COHAPTIC_SANITIZE STREQUAL "")
  if(NOT COHAPTIC_SANITIZE MATCHES "^(address,undefined|undefined,address|address|undefined|thread)$")
    message(FATAL_ERROR "COHAPTIC_SANITIZE: expected address,undefined or thread, found '${COHAPTIC_SANITIZE}'")
  endif()
  set(sanitize_flags -fsanitize=${COHAPTIC_SANITIZE} -fno-omit-frame-pointer)
  if(COHAPTIC_SANITIZE MATCHES "undefined")
    list(APPEND sanitize_flags -fsanitize=float-cast-overflow -fno-sanitize-recover=all)
  endif()
  add_compile_options(${sanitize_flags})
  add_link_options(${sanitize_flags})
  message(STATUS "cohaptic: sanitizers ${COHAPTIC_SANITIZE}")
endif()
