#pragma once
// Analytic shapes. They keep their own size (only real models are scaled to the unit cube).

#include "datasets/mesh.h"

namespace mcf {

/// Unit-radius icosphere: icosahedron subdivided 1-to-4 `level` times, projected to the sphere.
TriangleMesh make_icosphere(int level, double radius = 1.0);
/// Sphere with about `target_vertices` vertices (quasi-uniform, e.g. a Fibonacci-point hull or
/// an icosphere refined by an arbitrary frequency), radius `radius`, centred at the origin.
TriangleMesh make_sphere(long long target_vertices, double radius = 1.0);
/// Torus with major radius R, minor radius r, n_major x n_minor quads split into triangles.
TriangleMesh make_torus(double R, double r, int n_major, int n_minor);
/// The paper's cubical spiral: a square-profile helix strip with boundary.
TriangleMesh make_cubical_spiral(int turns, int segments_per_turn, int profile_segments);
/// Dumbbell: two spheres joined by a thin neck (closed, genus 0).
TriangleMesh make_dumbbell(int resolution);
/// Closed cylinder with rounded (hemispherical) caps.
TriangleMesh make_rounded_cylinder(double radius, double length, int resolution);
/// Open cylinder (two boundary loops).
TriangleMesh make_open_cylinder(double radius, double length, int n_around, int n_along);
/// Catenoid between z = -h and z = h (two boundary loops).
TriangleMesh make_catenoid(double waist, double height, int n_around, int n_along);

}  // namespace mcf
