// Shared by the OpenSubdiv harnesses (osd_loop, osd_stencils, osd_bfr): the one set of options
// they all compare with hybridsub, and the point type Far interpolates.
#pragma once

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

// The base level of `mesh` for the Loop scheme, VTX_BOUNDARY_EDGE_ONLY, CREASE_UNIFORM, the
// edges of `creases` ("i j" pairs, flattened) infinitely sharp (Sdc::Crease::SHARPNESS_INFINITE).
// The caller owns the result (TopologyRefinerFactory::Create's contract).
inline OpenSubdiv::Far::TopologyRefiner* create_loop_refiner(const harness::Mesh& mesh,
                                                           const std::vector<int>& creases) {
    using namespace OpenSubdiv;
    const std::vector<float> sharpness(creases.size() / 2, Sdc::Crease::SHARPNESS_INFINITE);
    const std::vector<int> verts_per_face(mesh.n_faces(), 3);
    Far::TopologyDescriptor desc;
    desc.numVertices = mesh.n_vertices();
    desc.numFaces = mesh.n_faces();
    desc.numVertsPerFace = verts_per_face.data();
    desc.vertIndicesPerFace = mesh.F.data();
    desc.numCreases = int(sharpness.size());
    desc.creaseVertexIndexPairs = creases.data();
    desc.creaseWeights = sharpness.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    sdc.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    Far::TopologyRefiner* refiner = Factory::Create(desc, Factory::Options(Sdc::SCHEME_LOOP, sdc));
    if (!refiner) throw std::runtime_error("TopologyRefinerFactory::Create failed");
    return refiner;
}

}  // namespace osd_common
