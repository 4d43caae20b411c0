// Measures of a triangle mesh: topology (watertight, manifold, winding),
// enclosed volume and distance of its vertices from the true surface.
// Topology is by vertex index; after weldByPosition() (which meshScene runs)
// that is also by position, as a reader of the written file sees it.
#pragma once
#include <optional>

#include "eval/evaluator.h"
#include "mesher.h"

namespace sdfc {

struct MeshTopology {
  size_t vertices = 0;  // referenced by some triangle
  size_t edges = 0;
  size_t boundary_edges = 0;       // used by one triangle
  size_t non_manifold_edges = 0;   // used by more than two
  size_t inconsistent_edges = 0;   // two triangles traverse it the same way
  size_t non_manifold_vertices = 0;  // triangles around it are not one fan
  size_t degenerate_triangles = 0;   // zero area
  long euler = 0;                    // V - E + F
  // Where the first non-manifold edge or vertex (else boundary edge) is.
  std::optional<glm::dvec3> problem_at;
  bool closedManifold() const {
    return boundary_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0 &&
           non_manifold_vertices == 0;
  }
};
MeshTopology checkTopology(const TriangleMesh& mesh);

// Signed volume by the divergence theorem (positive for outward winding).
double meshVolume(const TriangleMesh& mesh);

// max |distance| of the vertices, by the float64 evaluator.
double maxVertexError(const Evaluator& eval, const TriangleMesh& mesh, int threads = 0);

}  // namespace sdfc
