#!/bin/sh
# Runs a unit test program ("$@") with glibc's malloc mapping on transparent huge pages
# (where /sys/kernel/mm/transparent_hugepage allows them), taking blocks up to 32 MB from its
# heap and never trimming it: see tests/CMakeLists.txt. Tunables already set come after
# these, so a caller's own settings win.
GLIBC_TUNABLES="glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=4611686018427387904${GLIBC_TUNABLES:+:$GLIBC_TUNABLES}"
export GLIBC_TUNABLES
exec "$@"
