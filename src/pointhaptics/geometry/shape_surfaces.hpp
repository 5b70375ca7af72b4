#pragma once
/// @file The exact boundaries of the scene's solid shapes as closed triangle surfaces (what the eye sees and
/// the hand touches of a box, a sphere or a half-sphere), at a chosen edge length.
#include <pointhaptics/geometry/triangle_mesh.hpp>

namespace pointhaptics {

/// The box [origin, origin + size]: each face a grid of ceil(side / edge) intervals per side, split into
/// two triangles per cell; the faces share their border vertices, so the surface is closed; vertices lie
/// on the box's true faces. Counter-clockwise seen from outside.
TriangleMesh box_surface(const Vec3& origin, const Vec3& size, double edge);

/// The sphere as a "cube sphere": a cube's faces, each an n x n grid (n = ceil((pi / 2) r / edge)), pushed
/// onto the sphere along equal angles (u -> tan(pi u / 4)), so the edges vary by less than 1.5x and every
/// vertex lies on the sphere. Closed and outward like the cube.
TriangleMesh sphere_surface(const Vec3& centre, double radius, double edge);

/// The half ball y >= centre.y (sample_half_sphere's solid): the upper half of the cube sphere (n made even,
/// so its equator is a ring of vertices on the plane) and a flat disk closing it, the lower half mapped onto
/// the plane by the azimuthal equidistant projection (polar angle from the bottom -> radius), which keeps
/// its edges near `edge` and shares the equator ring.
TriangleMesh half_sphere_surface(const Vec3& centre, double radius, double edge);

}  // namespace pointhaptics
