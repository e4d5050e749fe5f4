// Times OpenSubdiv Far's uniform Loop refinement and the interpolation of positions.
//
// usage: osd_loop MESH.off LEVELS [--creases PAIRS.txt] [--repeat N] [--warmup W] [--out RESULT.off]
//
// Options: Loop scheme, VTX_BOUNDARY_EDGE_ONLY, CREASE_UNIFORM; the edges listed in
// --creases ("i j" per line) get sharpness 10 (Sdc::Crease::SHARPNESS_INFINITE). Positions are
// interpolated in double precision (PrimvarRefinerReal<double>), one level after the other,
// keeping only the previous level's buffer.
//
// Each repetition times, separately and in total:
//   create       TopologyRefinerFactory::Create (the base level's topology, from the faces;
//                osd_common.h, with its descriptor)
//   refine       RefineUniform(LEVELS)
//   interpolate  allocating each level's positions and PrimvarRefiner::Interpolate
// The refiner and buffers are destroyed (not timed) before the next repetition.
// Prints one JSON object; --out writes the last result (17 significant digits).
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/sdc/crease.h>
#include <opensubdiv/version.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "harness.h"
#include "osd_common.h"

using namespace OpenSubdiv;

using Point = osd_common::Point<double>;

#define STR2(x) #x
#define STR(x) STR2(x)

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 2) {
        std::fprintf(stderr, "usage: osd_loop MESH.off LEVELS [--creases PAIRS.txt] [--repeat N] [--warmup W] [--out RESULT.off]\n");
        return 2;
    }
    const harness::Mesh mesh = harness::read_off(args.pos[0]);
    const int levels = std::stoi(args.pos[1]);
    const int repeat = std::stoi(args.get("repeat", "5"));
    const int warmup = std::stoi(args.get("warmup", "1"));
    if (levels < 1 || levels > 15) throw std::runtime_error("LEVELS must be in 1..15");
    std::vector<int> creases;
    if (!args.get("creases").empty()) creases = harness::read_pairs(args.get("creases"));
    const std::vector<Point> coarse(reinterpret_cast<const Point*>(mesh.V.data()),
                                    reinterpret_cast<const Point*>(mesh.V.data()) + mesh.n_vertices());
    std::vector<double> t_create, t_refine, t_interp, t_total;
    long nv = 0, nf = 0;
    long peak = -1;
    for (int r = 0; r < warmup + repeat; ++r) {
        std::unique_ptr<Far::TopologyRefiner> refiner;
        std::vector<Point> src;
        double t0 = 0, t1 = 0, t2 = 0, t3 = 0;
        auto timed = [&] {
            t0 = harness::now();
            refiner.reset(osd_common::create_loop_refiner(mesh, creases));
            t1 = harness::now();
            refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(levels));
            t2 = harness::now();
            Far::PrimvarRefinerReal<double> primvar(*refiner);
            src = coarse;  // a copy of the input: the caller's buffer is not overwritten
            for (int level = 1; level <= levels; ++level) {
                std::vector<Point> dst(refiner->GetLevel(level).GetNumVertices());
                primvar.Interpolate(level, src, dst);
                src.swap(dst);
            }
            t3 = harness::now();
        };
        if (r == 0) peak = harness::peak_rss_growth(timed);  // the (untimed) warm-up run when warmup > 0
        else timed();
        if (r >= warmup) {
            t_create.push_back(t1 - t0);
            t_refine.push_back(t2 - t1);
            t_interp.push_back(t3 - t2);
            t_total.push_back(t3 - t0);
        }
        const Far::TopologyLevel& last = refiner->GetLevel(levels);
        nv = last.GetNumVertices();
        nf = last.GetNumFaces();
        if (r == warmup + repeat - 1 && !args.get("out").empty()) {
            harness::Mesh out;
            out.V.assign(reinterpret_cast<const double*>(src.data()), reinterpret_cast<const double*>(src.data()) + 3 * src.size());
            for (int f = 0; f < nf; ++f) {
                Far::ConstIndexArray fv = last.GetFaceVertices(f);
                out.F.insert(out.F.end(), {fv[0], fv[1], fv[2]});
            }
            harness::write_off(args.get("out"), out);
        }
    }
    std::printf("{\"peer\": \"OpenSubdiv %d.%d.%d Far Loop\", \"scheme\": \"loop\", \"levels\": %d, \"repeat\": %d, "
                "\"n_creases\": %zu, \"n_vertices\": %ld, \"n_faces\": %ld, \"peak_rss_delta\": %ld, %s, %s, %s, %s}\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH, levels, repeat,
                creases.size() / 2, nv, nf, peak, harness::json_timing("subdivide", t_total).c_str(),
                harness::json_timing("create", t_create).c_str(), harness::json_timing("refine", t_refine).c_str(),
                harness::json_timing("interpolate", t_interp).c_str());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "osd_loop: %s\n", e.what());
    return 1;
}
