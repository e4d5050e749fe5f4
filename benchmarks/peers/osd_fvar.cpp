// OpenSubdiv Far's uniform Loop refinement of a textured mesh: positions and one face-varying
// channel (UVs with seams) under a chosen Sdc::Options::FVarLinearInterpolation.
//
// usage: osd_fvar MESH.off UVS.txt LEVELS MODE [--creases PAIRS.txt] --out PREFIX
//
// UVS.txt: "t k m" on the first line, then t lines of k values (the UV values), then m lines of
// three UV indices (FUV, row f for face f of MESH.off). MODE is one of none, corners_only,
// corners_plus1, corners_plus2, boundaries, all (FVAR_LINEAR_NONE ... FVAR_LINEAR_ALL).
// Options otherwise those of osd_common.h: Loop, VTX_BOUNDARY_EDGE_ONLY, CREASE_UNIFORM, the
// listed creases infinitely sharp. Interpolation in double precision.
// Writes PREFIX.off (refined positions and faces, 17 significant digits) and PREFIX.uv (the
// refined UV values and FUV in the format of UVS.txt).
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/sdc/crease.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness.h"
#include "osd_common.h"

using namespace OpenSubdiv;

namespace {

// k values per UV (k <= 4) for PrimvarRefiner::InterpolateFaceVarying.
struct Value {
    double x[4];
    void Clear() { x[0] = x[1] = x[2] = x[3] = 0; }
    void AddWithWeight(const Value& s, double w) {
        for (int i = 0; i < 4; ++i) x[i] += w * s.x[i];
    }
};

Sdc::Options::FVarLinearInterpolation parse_mode(const std::string& mode) {
    static const std::map<std::string, Sdc::Options::FVarLinearInterpolation> modes = {
        {"none", Sdc::Options::FVAR_LINEAR_NONE},
        {"corners_only", Sdc::Options::FVAR_LINEAR_CORNERS_ONLY},
        {"corners_plus1", Sdc::Options::FVAR_LINEAR_CORNERS_PLUS1},
        {"corners_plus2", Sdc::Options::FVAR_LINEAR_CORNERS_PLUS2},
        {"boundaries", Sdc::Options::FVAR_LINEAR_BOUNDARIES},
        {"all", Sdc::Options::FVAR_LINEAR_ALL}};
    auto it = modes.find(mode);
    if (it == modes.end()) throw std::runtime_error("unknown MODE " + mode);
    return it->second;
}

}  // namespace

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 4 || args.get("out").empty()) {
        std::fprintf(stderr, "usage: osd_fvar MESH.off UVS.txt LEVELS MODE [--creases PAIRS.txt] --out PREFIX\n");
        return 2;
    }
    const harness::Mesh mesh = harness::read_off(args.pos[0]);
    const int levels = std::stoi(args.pos[2]);
    if (levels < 1 || levels > 8) throw std::runtime_error("LEVELS must be in 1..8");
    const auto mode = parse_mode(args.pos[3]);
    std::ifstream uvin(args.pos[1]);
    if (!uvin) throw std::runtime_error("cannot open " + args.pos[1]);
    int t = 0, k = 0, m = 0;
    uvin >> t >> k >> m;
    if (k < 1 || k > 4 || m != mesh.n_faces()) throw std::runtime_error("bad UV header");
    std::vector<Value> uv(t);
    for (auto& v : uv) {
        v.Clear();
        for (int i = 0; i < k; ++i) uvin >> v.x[i];
    }
    std::vector<int> fuv(3 * m);
    for (auto& i : fuv) uvin >> i;
    if (!uvin) throw std::runtime_error(args.pos[1] + ": truncated");
    osd_common::LoopTags tags;
    if (!args.get("creases").empty()) tags.creases = harness::read_pairs(args.get("creases"));
    tags.fvar = mode;
    tags.fvar_values = t;
    tags.fvar_indices = fuv.data();
    std::unique_ptr<Far::TopologyRefiner> refiner(osd_common::create_tagged_loop_refiner(mesh, tags));
    Far::TopologyRefiner::UniformOptions uniform(levels);
    uniform.fullTopologyInLastLevel = true;
    refiner->RefineUniform(uniform);

    using Point = osd_common::Point<double>;
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    std::vector<Point> X(reinterpret_cast<const Point*>(mesh.V.data()),
                         reinterpret_cast<const Point*>(mesh.V.data()) + mesh.n_vertices());
    for (int level = 1; level <= levels; ++level) {
        std::vector<Point> dst(refiner->GetLevel(level).GetNumVertices());
        primvar.Interpolate(level, X, dst);
        X.swap(dst);
        std::vector<Value> udst(refiner->GetLevel(level).GetNumFVarValues(0));
        primvar.InterpolateFaceVarying(level, uv, udst, 0);
        uv.swap(udst);
    }
    const Far::TopologyLevel& last = refiner->GetLevel(levels);
    harness::Mesh out;
    out.V.assign(reinterpret_cast<const double*>(X.data()), reinterpret_cast<const double*>(X.data()) + 3 * X.size());
    const std::string prefix = args.get("out");
    FILE* f = std::fopen((prefix + ".uv").c_str(), "w");
    if (!f) throw std::runtime_error("cannot write " + prefix + ".uv");
    std::fprintf(f, "%zu %d %d\n", uv.size(), k, last.GetNumFaces());
    for (const auto& v : uv) {
        for (int i = 0; i < k; ++i) std::fprintf(f, i ? " %.17g" : "%.17g", v.x[i]);
        std::fprintf(f, "\n");
    }
    for (int face = 0; face < last.GetNumFaces(); ++face) {
        Far::ConstIndexArray fv = last.GetFaceVertices(face);
        Far::ConstIndexArray fu = last.GetFaceFVarValues(face, 0);
        out.F.insert(out.F.end(), {fv[0], fv[1], fv[2]});
        std::fprintf(f, "%d %d %d\n", fu[0], fu[1], fu[2]);
    }
    std::fclose(f);
    harness::write_off(prefix + ".off", out);
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "osd_fvar: %s\n", e.what());
    return 1;
}
