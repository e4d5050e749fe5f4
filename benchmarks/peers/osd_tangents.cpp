// OpenSubdiv Far's limit positions and tangents of a Loop mesh's vertices: the reference for
// hybridsub.limit_tangents (tests/data/tangents/, written by
// benchmarks/peers/osd_tangents_references.py).
//
// usage: osd_tangents MESH.off LEVELS [--creases PAIRS.txt] --out RESULT.txt
//
// Options of osd_common.h (Loop, VTX_BOUNDARY_EDGE_ONLY, CREASE_UNIFORM, the edges of --creases
// infinitely sharp). After RefineUniform(LEVELS) (0: the input itself), positions are
// interpolated level by level and PrimvarRefinerReal<double>::Limit(src, pos, tan1, tan2)
// gives the limit position and the two tangents (Sdc's limit tangent masks, not normalised)
// of every vertex of the last level. --out writes one line a vertex: px py pz t1x t1y t1z
// t2x t2y t2z (17 significant digits).
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/version.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "harness.h"
#include "osd_common.h"

using namespace OpenSubdiv;

using Point = osd_common::Point<double>;

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 2 || args.get("out").empty()) {
        std::fprintf(stderr, "usage: osd_tangents MESH.off LEVELS [--creases PAIRS.txt] --out RESULT.txt\n");
        return 2;
    }
    const harness::Mesh mesh = harness::read_off(args.pos[0]);
    const int levels = std::stoi(args.pos[1]);
    if (levels < 0 || levels > 6) throw std::runtime_error("LEVELS must be in 0..6");
    std::vector<int> creases;
    if (!args.get("creases").empty()) creases = harness::read_pairs(args.get("creases"));
    std::unique_ptr<Far::TopologyRefiner> refiner(osd_common::create_loop_refiner(mesh, creases));
    Far::TopologyRefiner::UniformOptions uniform(levels);
    uniform.fullTopologyInLastLevel = true;  // PrimvarRefiner::Limit needs it
    if (levels) refiner->RefineUniform(uniform);
    const std::vector<Point> src = osd_common::interpolate_uniformly(*refiner, mesh, levels);
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    const int n = int(src.size());
    std::vector<Point> pos(n), tan1(n), tan2(n);
    primvar.Limit(src, pos, tan1, tan2);
    FILE* out = std::fopen(args.get("out").c_str(), "w");
    if (!out) throw std::runtime_error("cannot write " + args.get("out"));
    for (int v = 0; v < n; ++v) {
        std::fprintf(out, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", pos[v].p[0], pos[v].p[1],
                     pos[v].p[2], tan1[v].p[0], tan1[v].p[1], tan1[v].p[2], tan2[v].p[0], tan2[v].p[1], tan2[v].p[2]);
    }
    std::fclose(out);
    std::printf("{\"peer\": \"OpenSubdiv %d.%d.%d Far Loop limit tangents\", \"levels\": %d, \"n_vertices\": %d}\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH, levels, n);
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "osd_tangents: %s\n", e.what());
    return 1;
}
