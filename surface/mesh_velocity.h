// Per-vertex velocities of a surface mesh (issue 36), so that a renderer or Blender can blur it: at each vertex
// the Shepard average of the particles' velocities with ZB05's weights (1 - (r / R)^2)^3 over the support R, as
// the VDB's velocity grid is (particle_field.h); a vertex no particle reaches takes the nearest particle's in
// the cells around it (within R to 3.4 R: a splash thinner than the support), or none. Written as the mesh
// PLY's vx vy vz.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/mesh.h"

namespace surge {

// Fills mesh.velocities, one per vertex, from particles at x moving at v. The same at any thread count.
void sampleVertexVelocities(TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& x,
                            const std::vector<Eigen::Vector3f>& v, float support);

}  // namespace surge
