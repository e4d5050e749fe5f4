// Times OpenSubdiv's stencil tables: the "refine once, apply to every frame" path of Far.
//
// usage: osd_stencils MESH.off LEVELS [--repeat N] [--warmup W] [--threads T] [--out RESULT.off]
//
// Loop scheme with the options of osd_loop.cpp (osd_common.h), no creases. Each repetition times:
//   refine        TopologyRefinerFactory::Create + RefineUniform(LEVELS)
//   stencils      StencilTableFactory::Create, last level only, factorized onto the control
//                 vertices (generateIntermediateLevels = false), float weights
//   update        StencilTable::UpdateValues of float positions into a buffer allocated once
//                 (one frame, serial: Far's own loop)
//   update_double StencilTableReal<double> (StencilTableFactoryReal<double>) applied to double
//                 positions, the same way
//   update_omp    Osd::OmpEvaluator::EvalStencils of the float table with --threads threads
//                 (default: OpenMP's default)
// stencils_cpu, update_cpu, update_double_cpu: the same sections in process CPU time (serial
// sections: the time this process held a core, whatever else ran on the machine).
// Prints one JSON object; --out writes the float table's frame with the last level's faces.
#include <omp.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/osd/bufferDescriptor.h>
#include <opensubdiv/osd/ompEvaluator.h>
#include <opensubdiv/version.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "harness.h"
#include "osd_common.h"

using namespace OpenSubdiv;

template <typename REAL>
using Point = osd_common::Point<REAL>;

#define STR2(x) #x
#define STR(x) STR2(x)

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 2) {
        std::fprintf(stderr, "usage: osd_stencils MESH.off LEVELS [--repeat N] [--warmup W] [--threads T] [--out RESULT.off]\n");
        return 2;
    }
    const harness::Mesh mesh = harness::read_off(args.pos[0]);
    const int levels = std::stoi(args.pos[1]);
    const int repeat = std::stoi(args.get("repeat", "5"));
    const int warmup = std::stoi(args.get("warmup", "1"));
    const int threads = std::stoi(args.get("threads", "0"));
    if (levels < 1 || levels > 10) throw std::runtime_error("LEVELS must be in 1..10");
    if (threads > 0) omp_set_num_threads(threads);
    const int n = mesh.n_vertices();
    std::vector<Point<float>> src_f(n);
    std::vector<Point<double>> src_d(n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < 3; ++j) {
            src_f[i].p[j] = float(mesh.V[3 * i + j]);
            src_d[i].p[j] = mesh.V[3 * i + j];
        }
    std::vector<double> t_refine, t_stencils, t_update, t_double, t_omp, c_stencils, c_update, c_double;
    long nv = 0, nf = 0, nnz = 0;
    for (int r = 0; r < warmup + repeat; ++r) {
        const double t0 = harness::now();
        std::unique_ptr<Far::TopologyRefiner> refiner(osd_common::create_loop_refiner(mesh, {}));
        refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(levels));
        const double t1 = harness::now(), c1 = harness::cpu_now();
        Far::StencilTableFactory::Options so;
        so.generateIntermediateLevels = false;
        so.factorizeIntermediateLevels = true;
        so.generateOffsets = true;
        std::unique_ptr<const Far::StencilTable> table(Far::StencilTableFactory::Create(*refiner, so));
        const double t2 = harness::now(), c2 = harness::cpu_now();
        Far::StencilTableFactoryReal<double>::Options sod;
        sod.generateIntermediateLevels = false;
        sod.factorizeIntermediateLevels = true;
        sod.generateOffsets = true;
        std::unique_ptr<const Far::StencilTableReal<double>> table_d(
            Far::StencilTableFactoryReal<double>::Create(*refiner, sod));
        const int rows = table->GetNumStencils();
        std::vector<Point<float>> dst_f(rows);  // allocated and touched once, as a frame loop reuses it
        std::vector<Point<double>> dst_d(rows);
        table->UpdateValues(src_f.data(), dst_f.data());
        table_d->UpdateValues(src_d.data(), dst_d.data());
        const double t3 = harness::now(), c3 = harness::cpu_now();
        table->UpdateValues(src_f.data(), dst_f.data());
        const double t4 = harness::now(), c4 = harness::cpu_now();
        table_d->UpdateValues(src_d.data(), dst_d.data());
        const double t5 = harness::now(), c5 = harness::cpu_now();
        const Osd::BufferDescriptor bd(0, 3, 3);
        Osd::OmpEvaluator::EvalStencils(&src_f[0].p[0], bd, &dst_f[0].p[0], bd, &table->GetSizes()[0],
                                        &table->GetOffsets()[0], &table->GetControlIndices()[0],
                                        &table->GetWeights()[0], 0, rows);
        const double t6 = harness::now();
        if (r >= warmup) {
            t_refine.push_back(t1 - t0);
            t_stencils.push_back(t2 - t1);
            t_update.push_back(t4 - t3);
            t_double.push_back(t5 - t4);
            t_omp.push_back(t6 - t5);
            c_stencils.push_back(c2 - c1);
            c_update.push_back(c4 - c3);
            c_double.push_back(c5 - c4);
        }
        const Far::TopologyLevel& last = refiner->GetLevel(levels);
        nv = last.GetNumVertices();
        nf = last.GetNumFaces();
        nnz = long(table->GetControlIndices().size());
        if (rows != nv) throw std::runtime_error("stencil count differs from the last level's vertex count");
        if (r == warmup + repeat - 1 && !args.get("out").empty()) {
            harness::Mesh out;
            out.V.assign(&dst_f[0].p[0], &dst_f[0].p[0] + 3 * size_t(rows));  // the float table's frame
            for (int f = 0; f < nf; ++f) {
                Far::ConstIndexArray fv = last.GetFaceVertices(f);
                out.F.insert(out.F.end(), {fv[0], fv[1], fv[2]});
            }
            harness::write_off(args.get("out"), out);
        }
    }
    std::printf("{\"peer\": \"OpenSubdiv %d.%d.%d Far StencilTable (Loop)\", \"levels\": %d, \"repeat\": %d, "
                "\"n_vertices\": %ld, \"n_faces\": %ld, \"nnz\": %ld, \"omp_threads\": %d, %s, %s, %s, %s, %s, %s, %s, %s}\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH, levels, repeat, nv, nf,
                nnz, omp_get_max_threads(), harness::json_timing("refine", t_refine).c_str(),
                harness::json_timing("stencils", t_stencils).c_str(), harness::json_timing("update", t_update).c_str(),
                harness::json_timing("update_double", t_double).c_str(), harness::json_timing("update_omp", t_omp).c_str(),
                harness::json_timing("stencils_cpu", c_stencils).c_str(), harness::json_timing("update_cpu", c_update).c_str(),
                harness::json_timing("update_double_cpu", c_double).c_str());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "osd_stencils: %s\n", e.what());
    return 1;
}
