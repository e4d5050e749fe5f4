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
    Sdc::Options sdc;
    if (mode == "edge_only") sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    else if (mode == "edge_and_corner") sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    else if (mode == "none") sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_NONE);
    else throw std::runtime_error("unknown --boundary " + mode);
    sdc.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    std::vector<int> creases, corners;
    std::vector<float> crease_s, corner_s;
    read_tagged(args.get("creases"), 2, creases, crease_s);
    read_tagged(args.get("corners"), 1, corners, corner_s);
    const std::vector<int> verts_per_face(mesh.n_faces(), 3);
    Far::TopologyDescriptor desc;
    desc.numVertices = mesh.n_vertices();
    desc.numFaces = mesh.n_faces();
    desc.numVertsPerFace = verts_per_face.data();
    desc.vertIndicesPerFace = mesh.F.data();
    desc.numCreases = int(crease_s.size());
    desc.creaseVertexIndexPairs = creases.data();
    desc.creaseWeights = crease_s.data();
    desc.numCorners = int(corner_s.size());
    desc.cornerVertexIndices = corners.data();
    desc.cornerWeights = corner_s.data();
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(desc, Factory::Options(Sdc::SCHEME_LOOP, sdc)));
    if (!refiner) throw std::runtime_error("TopologyRefinerFactory::Create failed");
    Far::TopologyRefiner::UniformOptions uniform(levels);
    uniform.fullTopologyInLastLevel = true;  // Limit needs the last level's full topology
    refiner->RefineUniform(uniform);
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    std::vector<Point> src(reinterpret_cast<const Point*>(mesh.V.data()),
                           reinterpret_cast<const Point*>(mesh.V.data()) + mesh.n_vertices());
    for (int level = 1; level <= levels; ++level) {
        std::vector<Point> dst(refiner->GetLevel(level).GetNumVertices());
        primvar.Interpolate(level, src, dst);
        src.swap(dst);
    }
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
