# libFuzzer harnesses of the file parsers (fuzz/): with SEMSEGMAP_FUZZ=ON the whole build is
# compiled by Debian's clang with coverage instrumentation for libFuzzer and the address and
# undefined-behaviour sanitizers, and the harnesses link libFuzzer's main. Its own build folder
# (`make fuzz` uses build-fuzz). Without clang or its fuzzer runtime (libclang-rt-14-dev) the
# harnesses are left out, saying so; the rest builds as usual.
option(SEMSEGMAP_FUZZ "libFuzzer harnesses of the parsers (clang, libclang-rt-14-dev)" OFF)
set(SEMSEGMAP_FUZZ_BUILT OFF)
if(SEMSEGMAP_FUZZ)
  include(CheckCXXSourceCompiles)
  set(fuzz_flags -fsanitize=fuzzer,address,undefined)
  set(CMAKE_REQUIRED_FLAGS "${fuzz_flags}")
  set(CMAKE_REQUIRED_LINK_OPTIONS ${fuzz_flags})
  check_cxx_source_compiles(
    "#include <cstddef>
     #include <cstdint>
     extern \"C\" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }"
    SEMSEGMAP_HAVE_LIBFUZZER)
  unset(CMAKE_REQUIRED_FLAGS)
  unset(CMAKE_REQUIRED_LINK_OPTIONS)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(STATUS "semsegmap: the fuzz harnesses are left out: they need clang (configure with "
                   "-DCMAKE_CXX_COMPILER=clang++), not ${CMAKE_CXX_COMPILER_ID}")
  elseif(NOT SEMSEGMAP_HAVE_LIBFUZZER)
    message(STATUS "semsegmap: the fuzz harnesses are left out: clang cannot link "
                   "-fsanitize=fuzzer (scripts/setup.sh installs libclang-rt-14-dev)")
  else()
    set(SEMSEGMAP_FUZZ_BUILT ON)
    # Everything the harnesses reach is instrumented; only the harnesses get libFuzzer's main.
    add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                        -fno-sanitize-recover=all)
    add_link_options(-fsanitize=address,undefined)
    # As in SEMSEGMAP_SANITIZE: PCL frees with plain free what Eigen would align itself.
    add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
    message(STATUS "semsegmap: the fuzz harnesses are built (fuzz/, make fuzz)")
  endif()
endif()
