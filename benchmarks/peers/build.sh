#!/usr/bin/env bash
# Compile the C++ peer harnesses with g++ -O2 into benchmarks/peers/bin/ (git-ignored).
# A harness whose library is missing is skipped with a message; compare.py then lists that
# peer as skipped. Install the libraries on Debian/Ubuntu with
#     apt-get install libcgal-dev libosd-dev
# usage: benchmarks/peers/build.sh [--force]     (rebuilds only what is out of date otherwise)
set -u
here="$(cd "$(dirname "$0")" && pwd)"
bin="$here/bin"
mkdir -p "$bin"
cxx="${CXX:-g++}"
flags="-O2 -DNDEBUG -std=c++17"
force=0; [ "${1:-}" = "--force" ] && force=1
status=0

if ! command -v "$cxx" >/dev/null 2>&1; then
    echo "skip cgal_subdiv: no C++ compiler ($cxx)"
    echo "skip osd_loop: no C++ compiler ($cxx)"
    echo "skip osd_bfr: no C++ compiler ($cxx)"
    echo "skip osd_stencils: no C++ compiler ($cxx)"
    echo "skip osd_vtags: no C++ compiler ($cxx)"
    echo "skip osd_holes: no C++ compiler ($cxx)"
    echo "skip osd_tangents: no C++ compiler ($cxx)"
    echo "skip osd_fvar: no C++ compiler ($cxx)"
    exit 0
fi

has_header() { echo "#include <$1>" | "$cxx" -std=c++17 -x c++ -fsyntax-only - >/dev/null 2>&1; }

build() {  # build NAME HEADER LIBS...
    local name=$1 header=$2; shift 2
    local src="$here/$name.cpp" out="$bin/$name"
    if ! has_header "$header"; then
        echo "skip $name: <$header> not found (apt-get install ${pkg[$name]})"
        return
    fi
    if [ $force = 0 ] && [ -x "$out" ] && [ "$out" -nt "$src" ] && [ "$out" -nt "$here/harness.h" ] && [ "$out" -nt "$here/osd_common.h" ]; then
        echo "ok   $name (up to date)"
        return
    fi
    if "$cxx" $flags -o "$out" "$src" "$@"; then
        echo "ok   $name"
    else
        echo "FAIL $name"
        status=1
    fi
}

declare -A pkg=([cgal_subdiv]=libcgal-dev [osd_loop]=libosd-dev [osd_bfr]=libosd-dev [osd_stencils]=libosd-dev [osd_vtags]=libosd-dev [osd_holes]=libosd-dev [osd_tangents]=libosd-dev [osd_fvar]=libosd-dev)
build cgal_subdiv CGAL/Surface_mesh.h
build osd_loop opensubdiv/far/topologyRefinerFactory.h -losdCPU
build osd_bfr opensubdiv/bfr/refinerSurfaceFactory.h -losdCPU
build osd_stencils opensubdiv/far/stencilTableFactory.h -fopenmp -losdCPU
build osd_vtags opensubdiv/far/topologyRefinerFactory.h -losdCPU
build osd_holes opensubdiv/far/topologyRefinerFactory.h -losdCPU
build osd_tangents opensubdiv/far/primvarRefiner.h -losdCPU
build osd_fvar opensubdiv/far/primvarRefiner.h -losdCPU
exit $status
