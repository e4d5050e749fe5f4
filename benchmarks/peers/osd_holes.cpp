// OpenSubdiv Far's uniform Loop refinement of a mesh with face holes: the reference for
// hybridsub's holes= (tests/data/holes/, written by benchmarks/peers/osd_holes_references.py).
//
// usage: osd_holes MESH.off LEVELS --holes HOLES.txt [--creases PAIRS.txt] --out RESULT.off
//
// Options of osd_common.h (Loop, VTX_BOUNDARY_EDGE_ONLY, CREASE_UNIFORM, the edges of --creases
// infinitely sharp); the faces listed in HOLES.txt (one index a line) are tagged as holes
// (Far::TopologyDescriptor::holeIndices). Positions are interpolated in double precision
// (PrimvarRefinerReal<double>). --out writes every vertex of the last level and the faces of
// that level that are not holes (TopologyLevel::IsFaceHole), in Far's order, 17 digits.
// Prints one JSON object: the counts of each level (vertices, faces, hole faces).
#include <opensubdiv/far/primvarRefiner.h>
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

using Point = osd_common::Point<double>;

static std::vector<int> read_indices(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::vector<int> out;
    int i;
    while (in >> i) out.push_back(i);
    return out;
}

int main(int argc, char** argv) try {
    harness::Args args(argc, argv);
    if (args.pos.size() != 2 || args.get("holes").empty() || args.get("out").empty()) {
        std::fprintf(stderr, "usage: osd_holes MESH.off LEVELS --holes HOLES.txt [--creases PAIRS.txt] --out RESULT.off\n");
        return 2;
    }
    const harness::Mesh mesh = harness::read_off(args.pos[0]);
    const int levels = std::stoi(args.pos[1]);
    if (levels < 1 || levels > 8) throw std::runtime_error("LEVELS must be in 1..8");
    std::vector<int> creases;
    if (!args.get("creases").empty()) creases = harness::read_pairs(args.get("creases"));
    const std::vector<int> holes = read_indices(args.get("holes"));
    for (int h : holes)
        if (h < 0 || h >= mesh.n_faces()) throw std::runtime_error("hole index out of range: " + std::to_string(h));

    osd_common::LoopTags tags;
    tags.creases = creases;
    tags.holes = holes;
    std::unique_ptr<Far::TopologyRefiner> refiner(osd_common::create_tagged_loop_refiner(mesh, tags));
    refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(levels));
    const std::vector<Point> src = osd_common::interpolate_uniformly(*refiner, mesh, levels);
    std::string counts;
    for (int level = 0; level <= levels; ++level) {
        const Far::TopologyLevel& l = refiner->GetLevel(level);
        int nh = 0;
        for (int f = 0; f < l.GetNumFaces(); ++f) nh += l.IsFaceHole(f);
        counts += (level ? ", " : "") + std::string("[") + std::to_string(l.GetNumVertices()) + ", " +
                  std::to_string(l.GetNumFaces()) + ", " + std::to_string(nh) + "]";
    }
    const Far::TopologyLevel& last = refiner->GetLevel(levels);
    harness::Mesh out;
    out.V.assign(reinterpret_cast<const double*>(src.data()), reinterpret_cast<const double*>(src.data()) + 3 * src.size());
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        if (last.IsFaceHole(f)) continue;
        Far::ConstIndexArray fv = last.GetFaceVertices(f);
        out.F.insert(out.F.end(), {fv[0], fv[1], fv[2]});
    }
    harness::write_off(args.get("out"), out);
    std::printf("{\"peer\": \"OpenSubdiv %d.%d.%d Far Loop holes\", \"levels\": %d, \"n_holes\": %zu, "
                "\"counts\": [%s]}\n", OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR,
                OPENSUBDIV_VERSION_PATCH, levels, holes.size(), counts.c_str());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "osd_holes: %s\n", e.what());
    return 1;
}
