// Evaluates OpenSubdiv Bfr's Loop limit surface at given points of the input faces, and times it.
//
// usage: osd_bfr MESH.off POINTS.txt [--creases PAIRS.txt] [--approx-smooth N] [--approx-sharp N]
//                [--repeat N] [--out RESULT.txt]
//
// POINTS.txt has one point per line, "face u v" (OpenSubdiv's triangle parameterization:
// corner 0 at (0,0), 1 at (1,0), 2 at (0,1)). Options as osd_loop (Loop, VTX_BOUNDARY_EDGE_ONLY,
// CREASE_UNIFORM, listed creases infinitely sharp); Bfr's default approximation levels (smooth
// 2, sharp 6) unless given. Points are evaluated face by face in their order: each face's
// surface is initialised and its patch points prepared once, then every point on it evaluated
// (P, Du, Dv, double precision). Each repetition times everything after the refiner is built:
//   setup     RefinerSurfaceFactory construction
//   evaluate  InitVertexSurface + PreparePatchPoints per face, Evaluate per point
// Prints one JSON object; --out writes "regular Px Py Pz Dux Duy Duz Dvx Dvy Dvz" per point
// (17 significant digits; regular is 1 where Bfr's surface is a regular patch, i.e. exact).
#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/sdc/crease.h>
#include <opensubdiv/version.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "harness.h"
#include "osd_common.h"

using namespace OpenSubdiv;

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 2) {
        std::fprintf(stderr, "usage: osd_bfr MESH.off POINTS.txt [--creases PAIRS.txt] [--approx-smooth N] "
                             "[--approx-sharp N] [--repeat N] [--out RESULT.txt]\n");
        return 2;
    }
    const harness::Mesh mesh = harness::read_off(args.pos[0]);
    std::vector<int> pf;
    std::vector<double> puv;
    {
        std::ifstream in(args.pos[1]);
        if (!in) throw std::runtime_error("cannot read " + args.pos[1]);
        int f; double u, v;
        while (in >> f >> u >> v) { pf.push_back(f); puv.push_back(u); puv.push_back(v); }
    }
    const int repeat = std::stoi(args.get("repeat", "3"));
    std::vector<int> creases;
    if (!args.get("creases").empty()) creases = harness::read_pairs(args.get("creases"));
    std::unique_ptr<Far::TopologyRefiner> refiner(osd_common::create_loop_refiner(mesh, creases));

    Bfr::RefinerSurfaceFactory<>::Options opts;
    if (!args.get("approx-smooth").empty()) opts.SetApproxLevelSmooth(std::stoi(args.get("approx-smooth")));
    if (!args.get("approx-sharp").empty()) opts.SetApproxLevelSharp(std::stoi(args.get("approx-sharp")));
    const size_t n = pf.size();
    std::vector<double> out(9 * n, 0.0);
    std::vector<int> regular(n, 0);
    std::vector<double> t_setup, t_eval;
    for (int r = 0; r < repeat; ++r) {
        const double t0 = harness::now();
        Bfr::RefinerSurfaceFactory<> factory(*refiner, opts);
        const double t1 = harness::now();
        Bfr::Surface<double> surface;
        Bfr::Surface<double>::PointDescriptor pd(3);
        std::vector<double> patch;
        int current = -1;
        bool valid = false;
        for (size_t i = 0; i < n; ++i) {
            if (pf[i] != current) {
                current = pf[i];
                valid = factory.InitVertexSurface<double>(current, &surface);
                if (valid) {
                    patch.resize(3 * size_t(surface.GetNumPatchPoints()));
                    surface.PreparePatchPoints(mesh.V.data(), pd, patch.data(), pd);
                }
            }
            if (!valid) continue;
            double* o = &out[9 * i];
            surface.Evaluate(&puv[2 * i], patch.data(), pd, o, o + 3, o + 6);
            regular[i] = surface.IsRegular() ? 1 : 0;
        }
        const double t2 = harness::now();
        t_setup.push_back(t1 - t0);
        t_eval.push_back(t2 - t1);
    }
    if (!args.get("out").empty()) {
        FILE* fo = std::fopen(args.get("out").c_str(), "w");
        if (!fo) throw std::runtime_error("cannot write " + args.get("out"));
        for (size_t i = 0; i < n; ++i) {
            std::fprintf(fo, "%d", regular[i]);
            for (int k = 0; k < 9; ++k) std::fprintf(fo, " %.17g", out[9 * i + k]);
            std::fprintf(fo, "\n");
        }
        std::fclose(fo);
    }
    std::printf("{\"peer\": \"OpenSubdiv %d.%d.%d Bfr Loop\", \"scheme\": \"loop\", \"n_points\": %zu, "
                "\"repeat\": %d, %s, %s}\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH, n, repeat,
                harness::json_timing("setup", t_setup).c_str(), harness::json_timing("evaluate", t_eval).c_str());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "osd_bfr: %s\n", e.what());
    return 1;
}
