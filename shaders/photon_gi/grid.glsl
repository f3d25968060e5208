// The splat grid's walk, shared by the gather (photon_gi/gather.comp) and the specular pass's distance
// maps (specular/map_indirect.comp): the 27 cells around a point hold every splat whose kernel reaches
// it exactly once (Splatting.cpp buildSplatGrid: a kernel wider than a cell is copied every third cell).
// llvmpipe ends an invocation's loops after 65535 iterations in total (its loop limiter), so the CPU
// splits the cells into slices of at most 27 * u_sliceLength candidates per point and dispatches once
// per slice, accumulating (docs/DEVELOPMENT.md): a walk covers entries [u_sliceBegin, u_sliceBegin +
// u_sliceLength) of every cell.
#ifndef RADIANT_PHOTON_GI_GRID
#define RADIANT_PHOTON_GI_GRID
layout(std430, binding = 6) readonly buffer Cells { uint cellStart[]; };

uniform vec3 u_gridOrigin;
uniform float u_cellSize;
uniform ivec3 u_gridDims;
uniform uint u_sliceBegin;
uniform uint u_sliceLength;
// The farthest any splat stored in a cell reaches outside it (h sqrt(1 + tolerance^2) of the widest
// kernel), or more than a cell when the grid holds copies (Splatting.cpp buildSplatGrid): a neighbour
// cell farther than this from the point holds nothing that reaches it, and the walk skips it (0, a
// program that does not set it: no cell is skipped).
uniform float u_walkReach;

// The cell holding x (may lie outside the grid: photonCellSlice skips what does).
ivec3 photonCellOf(vec3 x) { return ivec3(floor((x - u_gridOrigin) / u_cellSize)); }

// Neighbour k (0..26) of cell c, the cell of point x: false when it is outside the grid or farther from
// x than u_walkReach, else this slice's entries of it, [begin, end) of the photon buffer.
bool photonCellSlice(vec3 x, ivec3 c, int k, out uint begin, out uint end) {
  ivec3 q = c + ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
  begin = end = 0u;
  if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, u_gridDims))) return false;
  vec3 lo = u_gridOrigin + vec3(q) * u_cellSize;
  vec3 gap = max(max(lo - x, x - (lo + u_cellSize)), vec3(0.0));
  if (u_walkReach > 0.0 && dot(gap, gap) > u_walkReach * u_walkReach) return false;
  int cell = (q.z * u_gridDims.y + q.y) * u_gridDims.x + q.x;
  begin = cellStart[cell] + u_sliceBegin;
  end = min(cellStart[cell + 1], begin + u_sliceLength);
  return true;
}
#endif
