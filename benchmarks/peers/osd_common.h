// Shared by the OpenSubdiv harnesses: the base level they all build (Loop, CREASE_UNIFORM and
// the tags a harness gives), the point type Far interpolates, and the level-by-level interpolation.
#pragma once

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/sdc/crease.h>

#include <stdexcept>
#include <vector>

#include "harness.h"

namespace osd_common {

// A position for Far's PrimvarRefiner / StencilTable (Clear and AddWithWeight).
template <typename REAL>
struct Point {
    REAL p[3];
    void Clear() { p[0] = p[1] = p[2] = 0; }
    void AddWithWeight(const Point& s, REAL w) {
        p[0] += w * s.p[0];
        p[1] += w * s.p[1];
        p[2] += w * s.p[2];
    }
};

// What a harness tags on the base level: creases ("i j" pairs, flattened) with their sharpness
// (empty: all infinitely sharp, Sdc::Crease::SHARPNESS_INFINITE), corners with theirs (empty:
// all infinite), face holes, the boundary rule, and at most one face-varying channel (its value
// count and one index per face corner; none while fvar_indices is null).
struct LoopTags {
    std::vector<int> creases;
    std::vector<float> crease_sharpness;
    std::vector<int> corners;
    std::vector<float> corner_sharpness;
    std::vector<int> holes;
    OpenSubdiv::Sdc::Options::VtxBoundaryInterpolation boundary =
        OpenSubdiv::Sdc::Options::VTX_BOUNDARY_EDGE_ONLY;
    OpenSubdiv::Sdc::Options::FVarLinearInterpolation fvar = OpenSubdiv::Sdc::Options::FVAR_LINEAR_ALL;
    int fvar_values = 0;
    const int* fvar_indices = nullptr;
};

// The base level of `mesh` for the Loop scheme, CREASE_UNIFORM, with `tags`. The caller owns
// the result (TopologyRefinerFactory::Create's contract).
inline OpenSubdiv::Far::TopologyRefiner* create_tagged_loop_refiner(const harness::Mesh& mesh, const LoopTags& tags) {
    using namespace OpenSubdiv;
    const int n_creases = int(tags.creases.size() / 2), n_corners = int(tags.corners.size());
    const std::vector<float> crease_s = tags.crease_sharpness.empty()
        ? std::vector<float>(n_creases, Sdc::Crease::SHARPNESS_INFINITE) : tags.crease_sharpness;
    const std::vector<float> corner_s = tags.corner_sharpness.empty()
        ? std::vector<float>(n_corners, Sdc::Crease::SHARPNESS_INFINITE) : tags.corner_sharpness;
    if (int(crease_s.size()) != n_creases || int(corner_s.size()) != n_corners)
        throw std::runtime_error("one sharpness per crease and per corner");
    const std::vector<int> verts_per_face(mesh.n_faces(), 3);
    Far::TopologyDescriptor desc;
    desc.numVertices = mesh.n_vertices();
    desc.numFaces = mesh.n_faces();
    desc.numVertsPerFace = verts_per_face.data();
    desc.vertIndicesPerFace = mesh.F.data();
    desc.numCreases = n_creases;
    desc.creaseVertexIndexPairs = tags.creases.data();
    desc.creaseWeights = crease_s.data();
    desc.numCorners = n_corners;
    desc.cornerVertexIndices = tags.corners.data();
    desc.cornerWeights = corner_s.data();
    desc.numHoles = int(tags.holes.size());
    desc.holeIndices = tags.holes.data();
    Far::TopologyDescriptor::FVarChannel channel;
    if (tags.fvar_indices) {
        channel.numValues = tags.fvar_values;
        channel.valueIndices = tags.fvar_indices;
        desc.numFVarChannels = 1;
        desc.fvarChannels = &channel;
    }
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(tags.boundary);
    sdc.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    sdc.SetFVarLinearInterpolation(tags.fvar);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    Far::TopologyRefiner* refiner = Factory::Create(desc, Factory::Options(Sdc::SCHEME_LOOP, sdc));
    if (!refiner) throw std::runtime_error("TopologyRefinerFactory::Create failed");
    return refiner;
}

// The base level of `mesh` for the Loop scheme, VTX_BOUNDARY_EDGE_ONLY, CREASE_UNIFORM, the
// edges of `creases` ("i j" pairs, flattened) infinitely sharp. The caller owns the result.
inline OpenSubdiv::Far::TopologyRefiner* create_loop_refiner(const harness::Mesh& mesh,
                                                           const std::vector<int>& creases) {
    LoopTags tags;
    tags.creases = creases;
    return create_tagged_loop_refiner(mesh, tags);
}

// The positions of the last refined level of `refiner` (refined uniformly `levels` times; 0:
// the input's), interpolated from `mesh`'s level by level in double precision.
inline std::vector<Point<double>> interpolate_uniformly(const OpenSubdiv::Far::TopologyRefiner& refiner,
                                                        const harness::Mesh& mesh, int levels) {
    using P = Point<double>;
    OpenSubdiv::Far::PrimvarRefinerReal<double> primvar(refiner);
    std::vector<P> src(reinterpret_cast<const P*>(mesh.V.data()), reinterpret_cast<const P*>(mesh.V.data()) + mesh.n_vertices());
    for (int level = 1; level <= levels; ++level) {
        std::vector<P> dst(refiner.GetLevel(level).GetNumVertices());
        primvar.Interpolate(level, src, dst);
        src.swap(dst);
    }
    return src;
}

}  // namespace osd_common
