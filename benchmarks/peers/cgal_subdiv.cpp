// Times CGAL's Sqrt3_subdivision / Loop_subdivision on a Surface_mesh.
//
// usage: cgal_subdiv MESH.off sqrt3|loop LEVELS [--repeat N] [--warmup W] [--out RESULT.off]
//
// Each repetition copies the input Surface_mesh (not timed), then times the subdivision call
// alone; the result is destroyed before the next copy, so at most one result is alive.
// Prints one JSON object: {"subdivide": {"median", "min", "times"}, counts, versions}.
// --out writes the last result (17 significant digits) so compare.py can check it against
// hybridsub at 1e-12.
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>
#include <CGAL/version.h>

#include <cstdio>
#include <string>
#include <unordered_map>
#include <vector>

#include "harness.h"

using Kernel = CGAL::Simple_cartesian<double>;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = SurfaceMesh::Vertex_index;

static SurfaceMesh to_surface_mesh(const harness::Mesh& m) {
    SurfaceMesh sm;
    std::vector<VertexIndex> vid(m.n_vertices());
    for (int i = 0; i < m.n_vertices(); ++i)
        vid[i] = sm.add_vertex(Kernel::Point_3(m.V[3 * i], m.V[3 * i + 1], m.V[3 * i + 2]));
    for (int f = 0; f < m.n_faces(); ++f)
        if (sm.add_face(vid[m.F[3 * f]], vid[m.F[3 * f + 1]], vid[m.F[3 * f + 2]]) == SurfaceMesh::null_face())
            throw std::runtime_error("face " + std::to_string(f) + " is not manifold-compatible");
    return sm;
}

static harness::Mesh from_surface_mesh(const SurfaceMesh& sm) {
    harness::Mesh m;
    std::unordered_map<std::size_t, int> index;  // CGAL index -> 0..n-1 (robust to removed elements)
    for (VertexIndex v : sm.vertices()) {
        index[std::size_t(v)] = m.n_vertices();
        const auto& p = sm.point(v);
        m.V.insert(m.V.end(), {p.x(), p.y(), p.z()});
    }
    for (auto f : sm.faces())
        for (VertexIndex v : sm.vertices_around_face(sm.halfedge(f))) m.F.push_back(index[std::size_t(v)]);
    return m;
}

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 3) {
        std::fprintf(stderr, "usage: cgal_subdiv MESH.off sqrt3|loop LEVELS "
                             "[--repeat N] [--warmup W] [--out RESULT.off]\n");
        return 2;
    }
    const std::string scheme = args.pos[1];
    const int levels = std::stoi(args.pos[2]);
    const int repeat = std::stoi(args.get("repeat", "5"));
    const int warmup = std::stoi(args.get("warmup", "1"));
    if (scheme != "sqrt3" && scheme != "loop") throw std::runtime_error("scheme must be sqrt3 or loop");

    const SurfaceMesh input = to_surface_mesh(harness::read_off(args.pos[0]));
    auto run = [&](SurfaceMesh& sm) {
        auto np = CGAL::parameters::number_of_iterations(levels);
        if (scheme == "sqrt3") CGAL::Subdivision_method_3::Sqrt3_subdivision(sm, np);
        else CGAL::Subdivision_method_3::Loop_subdivision(sm, np);
    };

    std::vector<double> times;
    std::size_t nv = 0, nf = 0;
    long peak = -1;
    for (int r = 0; r < warmup + repeat; ++r) {
        SurfaceMesh sm = input;  // the copy is not timed
        double t0 = 0, t1 = 0;
        auto timed = [&] { t0 = harness::now(); run(sm); t1 = harness::now(); };
        if (r == 0) peak = harness::peak_rss_growth(timed);  // the (untimed) warm-up run when warmup > 0
        else timed();
        if (r >= warmup) times.push_back(t1 - t0);
        nv = sm.number_of_vertices();
        nf = sm.number_of_faces();
        if (r == warmup + repeat - 1 && !args.get("out").empty()) harness::write_off(args.get("out"), from_surface_mesh(sm));
    }
    std::printf("{\"peer\": \"CGAL %s Subdivision_method_3::%s\", \"scheme\": \"%s\", \"levels\": %d, "
                "\"repeat\": %d, \"n_vertices\": %zu, \"n_faces\": %zu, \"peak_rss_delta\": %ld, %s}\n",
                CGAL_VERSION_STR, scheme == "sqrt3" ? "Sqrt3_subdivision" : "Loop_subdivision", scheme.c_str(),
                levels, repeat, nv, nf, peak, harness::json_timing("subdivide", times).c_str());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "cgal_subdiv: %s\n", e.what());
    return 1;
}
