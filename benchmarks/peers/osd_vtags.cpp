// OpenSubdiv Far's uniform Loop refinement with the vertex options of hybridsub's
// boundary= and corner_sharpness=: the reference tests/data/vtags/ is generated with.
//
// usage: osd_vtags MESH.off LEVELS --boundary edge_only|edge_and_corner|none
//                  [--creases EDGES.txt] [--corners CORNERS.txt] --out REFINED.off [--limit LIMIT.txt]
//
// Options: Loop scheme, CREASE_UNIFORM, VtxBoundaryInterpolation from --boundary. --creases
// lists "i j s" per line (edge i-j with sharpness s), --corners "v s" (vertex v with
// sharpness s); a sharpness of 10 or more is Sdc::Crease::SHARPNESS_INFINITE. Positions are
// interpolated in double precision (PrimvarRefinerReal<double>) level by level; --out writes
// level LEVELS (17 significant digits) and, on stdout, the indices of its faces Far tags as
// holes (VTX_BOUNDARY_NONE makes the faces at the boundary holes); --limit writes the limit
// position of each vertex of level LEVELS (PrimvarRefiner::Limit), one "x y z" per line.
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/sdc/crease.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "harness.h"
#include "osd_common.h"

using namespace OpenSubdiv;
using Point = osd_common::Point<double>;

// "index... sharpness" rows of `width` indices each.
static void read_tagged(const std::string& path, int width, std::vector<int>& idx, std::vector<float>& sharp) {
    if (path.empty()) return;
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    int i[2];
    double s;
    while (true) {
        for (int k = 0; k < width; ++k) in >> i[k];
        in >> s;
        if (!in) break;
        for (int k = 0; k < width; ++k) idx.push_back(i[k]);
        sharp.push_back(s >= 10 ? Sdc::Crease::SHARPNESS_INFINITE : float(s));
    }
}

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 2 || args.get("out").empty()) {
        std::fprintf(stderr, "usage: osd_vtags MESH.off LEVELS --boundary MODE [--creases EDGES.txt] "
                             "[--corners CORNERS.txt] --out REFINED.off [--limit LIMIT.txt]\n");
        return 2;
    }
    const harness::Mesh mesh = harness::read_off(args.pos[0]);
    const int levels = std::stoi(args.pos[1]);
    if (levels < 0 || levels > 10) throw std::runtime_error("LEVELS must be in 0..10");
    const std::string mode = args.get("boundary", "edge_only");
    osd_common::LoopTags tags;
    if (mode == "edge_only") tags.boundary = Sdc::Options::VTX_BOUNDARY_EDGE_ONLY;
    else if (mode == "edge_and_corner") tags.boundary = Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER;
    else if (mode == "none") tags.boundary = Sdc::Options::VTX_BOUNDARY_NONE;
    else throw std::runtime_error("unknown --boundary " + mode);
    read_tagged(args.get("creases"), 2, tags.creases, tags.crease_sharpness);
    read_tagged(args.get("corners"), 1, tags.corners, tags.corner_sharpness);
    std::unique_ptr<Far::TopologyRefiner> refiner(osd_common::create_tagged_loop_refiner(mesh, tags));
    Far::TopologyRefiner::UniformOptions uniform(levels);
    uniform.fullTopologyInLastLevel = true;  // Limit needs the last level's full topology
    refiner->RefineUniform(uniform);
    std::vector<Point> src = osd_common::interpolate_uniformly(*refiner, mesh, levels);
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    const Far::TopologyLevel& last = refiner->GetLevel(levels);
    harness::Mesh out;
    out.V.assign(reinterpret_cast<const double*>(src.data()), reinterpret_cast<const double*>(src.data()) + 3 * src.size());
    std::printf("holes:");
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        Far::ConstIndexArray fv = last.GetFaceVertices(f);
        out.F.insert(out.F.end(), {fv[0], fv[1], fv[2]});
        if (last.IsFaceHole(f)) std::printf(" %d", f);
    }
    std::printf("\n");
    harness::write_off(args.get("out"), out);
    if (!args.get("limit").empty()) {
        std::vector<Point> limit(src.size());
        primvar.Limit(src, limit);
        FILE* f = std::fopen(args.get("limit").c_str(), "w");
        if (!f) throw std::runtime_error("cannot write " + args.get("limit"));
        for (const Point& p : limit) std::fprintf(f, "%.17g %.17g %.17g\n", p.p[0], p.p[1], p.p[2]);
        std::fclose(f);
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "osd_vtags: %s\n", e.what());
    return 1;
}
