// Welding by position: what a slicer or any STL reader sees. Dual
// contouring can put the vertices of two cells at one point (a crease lying
// on a cell face, e.g. a roof ridge on a lattice plane); by index the mesh is
// closed, but a reader that merges equal positions finds zero-area triangles
// and edges used by four triangles. weldByPosition() merges such vertices,
// drops the triangles that collapse and removes the zero-volume fins left
// where two triangles come to share all three corners.
#pragma once
#include "mesher.h"

namespace sdfc {

// The distance below which two vertices are one point: float32's
// resolution at the mesh's largest coordinate (the files hold float32),
// and never less than 1e-4 voxel: readers merge with tolerances of their own
// (trimesh rounds to 1e-8, near the origin float32 holds 1e-11 apart), and
// vertices that close are one point to any of them.
double weldTolerance(const TriangleMesh& mesh, double voxel);

// Merges vertices within `tolerance` (max-norm), drops collapsed triangles
// and fins, flips the longest edge of any remaining zero-area triangle, and
// removes unreferenced vertices. Keeps each triangle's material.
WeldStats weldByPosition(TriangleMesh& mesh, double tolerance);

}  // namespace sdfc
