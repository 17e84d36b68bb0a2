#pragma once
// Analytic shapes. They keep their own size (only real models are scaled to the unit cube).
// All are consistently oriented (counter-clockwise seen from outside / away from the axis),
// without duplicate vertices at seams or poles. Bad parameters throw MeshError.

#include "datasets/mesh.h"

namespace mcf {

/// Unit-radius icosphere: icosahedron subdivided 1-to-4 `level` times, projected to the sphere
/// after each level. Level L has 10·4^L + 2 vertices and 20·4^L faces (level 0: icosahedron).
TriangleMesh make_icosphere(int level, double radius = 1.0);
/// Sphere with about `target_vertices` vertices (quasi-uniform, e.g. a Fibonacci-point hull or
/// an icosphere refined by an arbitrary frequency), radius `radius`, centred at the origin.
/// Implementation: geodesic sphere of frequency k (each icosahedron edge split into k), the k
/// whose 10k² + 2 vertices are closest to the target, projected radially.
TriangleMesh make_sphere(long long target_vertices, double radius = 1.0);
/// Torus with major radius R, minor radius r, n_major x n_minor quads split into triangles,
/// axis z, centred at the origin. Genus 1. Requires R > r > 0.
TriangleMesh make_torus(double R = 1.0, double r = 0.3, int n_major = 96, int n_minor = 32);
/// The paper's cubical spiral: a square-profile helix strip with boundary. A vertical ribbon,
/// 0.6 high, that winds counter-clockwise around the z axis along a square of side 2 centred on
/// the axis, rising 1 per turn (0.4 gap between turns); one boundary loop (a disk topologically).
/// segments_per_turn is rounded up to a multiple of 4 so the square's corners are vertices;
/// profile_segments divide the ribbon's height.
TriangleMesh make_cubical_spiral(int turns = 3, int segments_per_turn = 128,
                                 int profile_segments = 8);
/// Dumbbell: two spheres joined by a thin neck (closed, genus 0). Surface of revolution about z:
/// unit spheres centred at z = ±1.5 joined by a smooth neck of radius 0.25; `resolution`
/// vertices around the widest rings, fewer on narrower rings (proportional to the radius, at
/// least 6) so triangles stay near-equilateral at the neck and the poles.
TriangleMesh make_dumbbell(int resolution = 64);
/// Closed cylinder with rounded (hemispherical) caps: the straight part spans
/// z in [-length/2, length/2]; `resolution` vertices around the cylinder, fewer on the cap
/// rings (as for the dumbbell). Genus 0.
TriangleMesh make_rounded_cylinder(double radius = 0.5, double length = 2.0, int resolution = 64);
/// Open cylinder (two boundary loops), axis z, z in [-length/2, length/2], faces oriented away
/// from the axis.
TriangleMesh make_open_cylinder(double radius = 0.5, double length = 2.0, int n_around = 64,
                                int n_along = 40);
/// Catenoid between z = -h and z = h (two boundary loops): ρ(z) = waist·cosh(z/waist), h = height.
/// The defaults (h/waist = 1 < 1.2) give the stable catenoid, a minimal surface MCF keeps.
TriangleMesh make_catenoid(double waist = 1.0, double height = 1.0, int n_around = 64,
                           int n_along = 24);

}  // namespace mcf
