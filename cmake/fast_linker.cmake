# The linker: LLVM's lld where it is installed (Debian: lld), else the toolchain's default.
# lld links a sanitizer build's test program (hundreds of MB with line tables) several times
# faster than GNU ld. -DCOHAPTIC_USE_LLD=OFF keeps the default linker.
include(CheckLinkerFlag)
option(COHAPTIC_USE_LLD "Link with lld when it is installed" ON)
if(COHAPTIC_USE_LLD)
  check_linker_flag(CXX -fuse-ld=lld COHAPTIC_HAVE_LLD)
  if(COHAPTIC_HAVE_LLD)
    add_link_options(-fuse-ld=lld)
    message(STATUS "cohaptic: linking with lld")
  endif()
endif()
