#pragma once
// Tangent frames by MikkTSpace (Mikkelsen, "Simulation of Wrinkled Surfaces Revisited", 2008; the
// algorithm of his mikktspace.c, written here for triangle lists): what glTF 2.0 (3.7.2.1) asks a client
// to compute when a normal-mapped primitive has no TANGENT attribute, and what exporters (Blender's)
// write when it has. A tangent belongs to a triangle corner, not to a vertex: corners that share a
// vertex get different tangents across uv seams and where mirrored uvs meet, so the mesh's vertices are
// split where their corners disagree (splitVerticesByTangent).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace radiant {

// One tangent per triangle corner (corner 3 t + k is corner k of triangle t), for the triangle list
// `indices` over positions, unit normals and uvs (one per vertex), as mikktspace.c's genTangSpaceDefault
// (angular threshold 180 degrees) returns them through setTSpaceBasic: xyz the unit tangent, w = +1
// where the triangle's uv map preserves orientation (the bitangent is w cross(n, t)), -1 where it
// mirrors. The steps, named after the paper and mikktspace.c:
//  1. corners with bit-identical position, normal and uv are welded (the same vertex for the rest);
//  2. a triangle with two equal positions is degenerate and takes no part in 3-5;
//  3. per triangle, the first-order derivatives dP/ds, dP/dt of the uv map (paper eq. 18, 19),
//     normalised and turned by the sign of the uv area; a triangle with zero uv area or a zero
//     derivative is "group with any" (it joins its neighbours' groups, taking their orientation);
//  4. per welded vertex, groups of triangles around it that are connected across shared edges and map
//     uvs with the same orientation (the "4 rules"), grown depth-first from each triangle in order;
//  5. per group, the tangent of each triangle's corner is the corner-angle-weighted mean of its
//     subgroup's derivatives projected into the normal's plane (the subgroup: the triangles whose
//     projected derivatives are within the angular threshold of its own, i.e. all of them at 180
//     degrees unless exactly opposite);
//  6. a degenerate triangle's corners copy the frame of the first healthy corner welded to them.
// A corner no group reaches (a triangle with no uv area and no healthy neighbour) keeps mikktspace.c's
// default, tangent (1, 0, 0) and w = -1; a caller that needs it perpendicular to the normal makes it so
// (the glTF loader's Gram-Schmidt). Never NaN or Inf: non-finite input gives the default frame.
// Groups of more than kMikkTSpaceMaxExactGroup triangles around one vertex (a hostile fan) take the
// whole group as one subgroup, which is what the 180-degree threshold gives unless two derivatives are
// exactly opposite: the exact subgroups cost the group size squared.
constexpr std::size_t kMikkTSpaceMaxExactGroup = 256;
std::vector<glm::vec4> mikkTSpaceCornerTangents(const std::vector<glm::vec3>& positions,
                                                const std::vector<glm::vec3>& normals,
                                                const std::vector<glm::vec2>& uvs,
                                                const std::vector<std::uint32_t>& indices);

// glTF's tangents: MikkTSpace over the uv set with v flipped, (u, 1 - v). glTF's v runs down the image
// while its normal maps' green channel points up it (3.9.3), so the bitangent must follow -dP/dv; an
// exporter computes MikkTSpace in its own uv space, where v runs up (Blender's), and writes the result
// unchanged. (The same tangents, with w negated, as MikkTSpace over (u, v).)
std::vector<glm::vec4> gltfMikkTSpaceCornerTangents(const std::vector<glm::vec3>& positions,
                                                    const std::vector<glm::vec3>& normals,
                                                    const std::vector<glm::vec2>& uvs,
                                                    const std::vector<std::uint32_t>& indices);

// An indexed triangle list whose vertices are split where the corners that share one got different
// tangents: new vertex v is a copy of vertex vertexOf[v] with tangent tangents[v]; `indices` is the
// triangle list over the new vertices. Corners of one vertex with bit-identical tangents stay one vertex.
struct TangentSplit {
  std::vector<std::uint32_t> vertexOf;
  std::vector<std::uint32_t> indices;
  std::vector<glm::vec4> tangents;
};
TangentSplit splitVerticesByTangent(const std::vector<glm::vec4>& cornerTangents,
                                    const std::vector<std::uint32_t>& indices);

}  // namespace radiant
