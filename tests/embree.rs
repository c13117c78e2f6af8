//! Integration tests of heron's Embree layer through its public API: closest hits
//! against analytic ray–sphere and ray–triangle intersections (computed in f64), ray
//! segment limits, occlusion, 8-wide packets against single rays, geometry IDs, input
//! validation, thread safety.
//!
//! Random rays come from a small seeded PCG32, so every run traces the same rays.
use std::sync::Arc;

use glam::{DVec3, Vec3};
use heron::accel::embree::{
    flush_denormals_enabled, worker_pool, Device, EmbreeError, Hit, RayCoherence, RayQuery, Scene,
    StreamScratch,
};

// ---------------------------------------------------------------------------------------
// Helpers

/// Deterministic test rays from heron's own PCG32 streams.
struct Pcg32(heron::math::Rng);

impl Pcg32 {
    fn new(seed: u64, stream: u64) -> Self {
        Pcg32(heron::math::Rng::new(seed, stream))
    }
    fn next_u32(&mut self) -> u32 {
        self.0.next_u32()
    }
    /// Uniform in [0, 1).
    fn f32(&mut self) -> f32 {
        self.0.uniform()
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    fn in_box(&mut self, half: f32) -> Vec3 {
        Vec3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }
    /// Uniform direction on the unit sphere.
    fn unit(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f32::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

fn device() -> Device {
    Device::new("").expect("Embree device")
}

fn ray(origin: Vec3, dir: Vec3) -> RayQuery {
    RayQuery {
        origin,
        dir,
        tnear: 0.0,
        tfar: f32::INFINITY,
    }
}

/// Both roots of |o + t d - c|² = r² in f64 (t0 <= t1), or None if the ray's line misses.
/// Also returns how far from tangent the ray is: the discriminant relative to |d|² r².
fn ray_sphere(o: Vec3, d: Vec3, c: Vec3, r: f32) -> Option<(f64, f64, f64)> {
    let (o, d, c, r) = (o.as_dvec3(), d.as_dvec3(), c.as_dvec3(), r as f64);
    let oc = o - c;
    let a = d.dot(d);
    let b = oc.dot(d);
    // Numerically stable form: distance² from the centre to the line.
    let perp = oc - d * (b / a);
    let disc = a * (r * r - perp.dot(perp));
    if disc < 0.0 {
        return None;
    }
    let q = disc.sqrt();
    let t0 = (-b - q) / a;
    let t1 = (-b + q) / a;
    Some((t0, t1, disc / (a * r * r)))
}

/// Möller–Trumbore in f64: (t, u, v) of the line through the triangle's plane, if the
/// line crosses the triangle, plus the distance to the nearest edge in barycentric units.
fn ray_triangle(o: Vec3, d: Vec3, p: [Vec3; 3]) -> Option<(f64, f64, f64, f64)> {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let [p0, p1, p2] = p.map(|v| v.as_dvec3());
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-12 {
        return None;
    }
    let tv = o - p0;
    let u = tv.dot(pv) / det;
    let qv = tv.cross(e1);
    let v = d.dot(qv) / det;
    let t = e2.dot(qv) / det;
    let edge = u.min(v).min(1.0 - u - v);
    (edge >= 0.0).then_some((t, u, v, edge))
}

fn assert_close(what: &str, got: f32, want: f64, rel: f64) {
    let err = (got as f64 - want).abs();
    assert!(
        err <= rel * want.abs().max(1.0),
        "{what}: got {got}, want {want} (error {err:e})"
    );
}

/// A few non-overlapping spheres for the sphere tests.
fn sphere_scene(device: &Device, rng: &mut Pcg32) -> (Scene, Vec<(Vec3, f32)>) {
    let mut spheres: Vec<(Vec3, f32)> = Vec::new();
    while spheres.len() < 6 {
        let c = rng.in_box(8.0);
        let r = rng.range(0.3, 2.0);
        if spheres
            .iter()
            .all(|&(c2, r2)| c.distance(c2) > r + r2 + 0.1)
        {
            spheres.push((c, r));
        }
    }
    let mut b = device.scene_builder();
    for (i, &(c, r)) in spheres.iter().enumerate() {
        assert_eq!(b.add_sphere(c, r).unwrap(), i as u32);
    }
    (b.commit().unwrap(), spheres)
}

/// Analytic closest sphere hit for t in [tnear, tfar]: (geom, t, margin), where margin is
/// how unambiguous the answer is (tangency and closeness to the segment ends).
fn closest_sphere(spheres: &[(Vec3, f32)], q: &RayQuery) -> (Option<(u32, f64)>, f64) {
    let mut best: Option<(u32, f64)> = None;
    let mut margin = f64::INFINITY;
    let dlen = q.dir.length() as f64;
    for (i, &(c, r)) in spheres.iter().enumerate() {
        if let Some((t0, t1, tangency)) = ray_sphere(q.origin, q.dir, c, r) {
            margin = margin.min(tangency);
            for t in [t0, t1] {
                // Distance (in world units) of this root from the segment ends.
                let end = ((t - q.tnear as f64).abs()).min((t - q.tfar as f64).abs()) * dlen;
                margin = margin.min(end / r as f64);
                if t >= q.tnear as f64 && t <= q.tfar as f64 && best.map_or(true, |b| t < b.1) {
                    best = Some((i as u32, t));
                }
            }
        }
    }
    (best, margin)
}

// ---------------------------------------------------------------------------------------
// Compile-time properties

const _: () = {
    const fn send_sync<T: Send + Sync>() {}
    send_sync::<Scene>();
    send_sync::<Device>();
    send_sync::<Hit>();
};

// ---------------------------------------------------------------------------------------
// Spheres

#[test]
fn sphere_hits_from_outside_match_analytic() {
    let dev = device();
    let mut rng = Pcg32::new(1, 1);
    let (scene, spheres) = sphere_scene(&dev, &mut rng);
    let (mut hits, mut misses, mut skipped) = (0, 0, 0);
    for _ in 0..20_000 {
        // Origin on a shell around the scene, aimed at a random point near a sphere, so
        // that most rays hit and some miss.
        let origin = rng.unit() * 30.0;
        let (c, r) = spheres[(rng.next_u32() % spheres.len() as u32) as usize];
        let target = c + rng.in_box(1.3 * r);
        let dir = (target - origin) * rng.range(0.2, 3.0); // not normalised
        let q = ray(origin, dir);
        let (want, margin) = closest_sphere(&spheres, &q);
        if margin < 1e-3 {
            skipped += 1;
            continue;
        }
        let got = scene.intersect1(&q);
        match (want, got) {
            (Some((geom, t)), Some(h)) => {
                hits += 1;
                assert_eq!(h.geom_id, geom, "ray {q:?}");
                assert_eq!(h.prim_id, 0);
                assert_close("sphere t", h.t, t, 2e-5);
                // Outward normal at the hit point.
                let (c, r) = spheres[geom as usize];
                let p = q.origin.as_dvec3() + q.dir.as_dvec3() * t;
                let n = (p - c.as_dvec3()) / r as f64;
                let ng = h.ng.as_dvec3();
                assert!(ng.normalize().dot(n) > 0.9999, "ng {ng} vs {n}");
            }
            (None, None) => misses += 1,
            (want, got) => panic!("ray {q:?}: analytic {want:?}, embree {got:?}"),
        }
    }
    assert!(
        hits > 5_000 && misses > 1_000,
        "{hits} hits, {misses} misses"
    );
    assert!(skipped < 200, "{skipped} ambiguous rays skipped");
}

#[test]
fn sphere_far_hit_from_inside() {
    let dev = device();
    let mut rng = Pcg32::new(2, 1);
    let (scene, spheres) = sphere_scene(&dev, &mut rng);
    for i in 0..5_000 {
        let geom = i % spheres.len();
        let (c, r) = spheres[geom];
        let origin = c + rng.unit() * r * rng.range(0.0, 0.95);
        let dir = rng.unit() * rng.range(0.5, 2.0);
        let q = ray(origin, dir);
        let (_, t1, _) = ray_sphere(origin, dir, c, r).expect("inside: always crosses");
        let h = scene
            .intersect1(&q)
            .expect("a ray from inside hits its sphere");
        assert_eq!(h.geom_id, geom as u32);
        assert_close("far t", h.t, t1, 2e-5);
        // Embree's sphere normal points outwards also for the far (exit) hit.
        assert!(
            h.ng.dot(dir) > 0.0,
            "exit normal {:?} along dir {dir}",
            h.ng
        );
        assert!(scene.occluded1(&q));
    }
}

#[test]
fn sphere_segment_limits_are_respected() {
    let dev = device();
    let mut b = dev.scene_builder();
    b.add_sphere(Vec3::new(0.0, 0.0, 10.0), 2.0).unwrap();
    let scene = b.commit().unwrap();
    let o = Vec3::ZERO;
    let d = Vec3::Z;
    let at = |tnear: f32, tfar: f32| {
        scene.intersect1(&RayQuery {
            origin: o,
            dir: d,
            tnear,
            tfar,
        })
    };
    // Roots at t = 8 and t = 12.
    assert_close("near", at(0.0, f32::INFINITY).unwrap().t, 8.0, 1e-6);
    assert_close("near, tfar just past", at(0.0, 8.01).unwrap().t, 8.0, 1e-6);
    assert!(at(0.0, 7.99).is_none(), "hit beyond tfar reported");
    assert_close(
        "tnear past near root",
        at(8.01, 100.0).unwrap().t,
        12.0,
        1e-6,
    );
    assert!(at(8.01, 11.99).is_none(), "hit beyond tfar reported");
    assert!(at(12.01, 100.0).is_none(), "hit before tnear reported");
    // Same for occlusion.
    let occ = |tnear: f32, tfar: f32| {
        scene.occluded1(&RayQuery {
            origin: o,
            dir: d,
            tnear,
            tfar,
        })
    };
    assert!(occ(0.0, f32::INFINITY));
    assert!(!occ(0.0, 7.99));
    assert!(occ(8.01, 100.0));
    assert!(!occ(8.01, 11.99));
    assert!(!occ(12.01, f32::INFINITY));
}

// ---------------------------------------------------------------------------------------
// Triangles

/// A mesh of random, independent triangles in a box, as (positions, indices).
fn random_triangles(rng: &mut Pcg32, n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for i in 0..n as u32 {
        let c = rng.in_box(5.0);
        for _ in 0..3 {
            positions.push(c + rng.in_box(1.5));
        }
        indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    (positions, indices)
}

#[test]
fn triangle_hits_match_analytic() {
    let dev = device();
    let mut rng = Pcg32::new(3, 1);
    let (positions, indices) = random_triangles(&mut rng, 40);
    let mut b = dev.scene_builder();
    assert_eq!(b.add_triangle_mesh(&positions, &indices).unwrap(), 0);
    let scene = b.commit().unwrap();
    let tri = |i: usize| indices[i].map(|k| positions[k as usize]);

    let (mut hits, mut misses, mut skipped) = (0, 0, 0);
    for _ in 0..20_000 {
        let origin = rng.unit() * 20.0 + rng.in_box(2.0);
        // Half the rays aim at a point of a random triangle (mostly hits), half at a
        // random point of the box (mostly misses).
        let target = if rng.f32() < 0.5 {
            let [p0, p1, p2] = tri((rng.next_u32() as usize) % indices.len());
            let (a, b) = (rng.f32(), rng.f32());
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            p0 + (p1 - p0) * a + (p2 - p0) * b
        } else {
            rng.in_box(6.0)
        };
        let q = RayQuery {
            origin,
            dir: (target - origin) * rng.range(0.1, 2.0),
            tnear: rng.range(0.0, 0.3),
            tfar: if rng.f32() < 0.5 {
                f32::INFINITY
            } else {
                rng.range(0.5, 3.0)
            },
        };
        // Closest analytic hit within [tnear, tfar]; skip rays that pass within a
        // relative 1e-4 of an edge or of a segment end (either answer is acceptable).
        let mut best: Option<(usize, f64, f64, f64)> = None;
        let mut ambiguous = false;
        let dlen = q.dir.length() as f64;
        for i in 0..indices.len() {
            if let Some((t, u, v, edge)) = ray_triangle(q.origin, q.dir, tri(i)) {
                let in_range = t >= q.tnear as f64 && t <= q.tfar as f64;
                let near_end =
                    ((t - q.tnear as f64).abs().min((t - q.tfar as f64).abs()) * dlen) < 1e-3;
                if edge < 1e-4 || (near_end && t > 0.0) {
                    ambiguous |= in_range || near_end;
                }
                if in_range && best.map_or(true, |b| t < b.1) {
                    best = Some((i, t, u, v));
                }
            }
        }
        // Two triangles at almost the same t: which one is "closest" is ambiguous.
        if let Some((i, t, ..)) = best {
            for j in 0..indices.len() {
                if j != i {
                    if let Some((t2, _, _, e2)) = ray_triangle(q.origin, q.dir, tri(j)) {
                        if e2 >= 0.0 && (t2 - t).abs() * dlen < 1e-3 {
                            ambiguous = true;
                        }
                    }
                }
            }
        }
        if ambiguous {
            skipped += 1;
            continue;
        }
        match (best, scene.intersect1(&q)) {
            (Some((i, t, u, v)), Some(h)) => {
                hits += 1;
                assert_eq!(h.geom_id, 0);
                assert_eq!(h.prim_id, i as u32, "ray {q:?}");
                // f32 error bounds: both t (in world units) and u, v degrade as the ray
                // grazes the plane (1/cos) and with the distance from the origin (the
                // scale of the coordinates Embree subtracts); measured worst cases are
                // about 2e-7 of these bounds' scale, so 1e-6 leaves a 5x margin.
                let [p0, p1, p2] = tri(i).map(|p| p.as_dvec3());
                let cos = ((p1 - p0).cross(p2 - p0).normalize().dot(q.dir.as_dvec3()) / dlen)
                    .abs()
                    .max(1e-6);
                let scale = q.origin.length() as f64 + 5.0;
                let size = (p1 - p0)
                    .length()
                    .min((p2 - p0).length())
                    .min((p2 - p1).length());
                let t_tol = 1e-6 * scale / cos / dlen;
                assert!(
                    (h.t as f64 - t).abs() <= t_tol,
                    "t {} vs {t} (tol {t_tol:e})",
                    h.t
                );
                let uv_tol = 1e-6 * scale / (cos * size);
                let uv_err = (h.u as f64 - u).abs().max((h.v as f64 - v).abs());
                assert!(uv_err <= uv_tol, "u,v {},{} vs {u},{v}", h.u, h.v);
                // Ng = (p1 - p0) × (p2 - p0), unnormalised.
                let [p0, p1, p2] = tri(i).map(|p| p.as_dvec3());
                let n: DVec3 = (p1 - p0).cross(p2 - p0);
                let ng = h.ng.as_dvec3();
                assert!((ng - n).length() <= 1e-4 * n.length(), "ng {ng} vs {n}");
            }
            (None, None) => misses += 1,
            (want, got) => panic!("ray {q:?}: analytic {want:?}, embree {got:?}"),
        }
    }
    assert!(
        hits > 5_000 && misses > 5_000,
        "{hits} hits, {misses} misses"
    );
    assert!(skipped < 1_000, "{skipped} ambiguous rays skipped");
}

#[test]
fn triangle_segment_limits_and_winding() {
    let dev = device();
    let mut b = dev.scene_builder();
    // Two parallel squares (two triangles each) at z = 2 and z = 5, counter-clockwise
    // seen from +z, i.e. Ng = +z.
    let positions: Vec<Vec3> = [2.0f32, 5.0]
        .iter()
        .flat_map(|&z| {
            [
                Vec3::new(-1.0, -1.0, z),
                Vec3::new(1.0, -1.0, z),
                Vec3::new(1.0, 1.0, z),
                Vec3::new(-1.0, 1.0, z),
            ]
        })
        .collect();
    let indices = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    b.add_triangle_mesh(&positions, &indices).unwrap();
    let scene = b.commit().unwrap();
    let q = |tnear: f32, tfar: f32| RayQuery {
        origin: Vec3::new(0.3, -0.2, 0.0),
        dir: Vec3::new(0.0, 0.0, 0.5),
        tnear,
        tfar,
    };
    // dir has length 0.5: the planes are at t = 4 and t = 10.
    let h = scene.intersect1(&q(0.0, f32::INFINITY)).unwrap();
    assert_close("t", h.t, 4.0, 1e-6);
    assert!(h.prim_id < 2);
    assert!(h.ng.normalize().abs_diff_eq(Vec3::Z, 1e-6), "ng {:?}", h.ng);
    assert!(scene.intersect1(&q(0.0, 3.99)).is_none());
    assert_close(
        "second plane",
        scene.intersect1(&q(4.01, 100.0)).unwrap().t,
        10.0,
        1e-6,
    );
    assert!(scene.intersect1(&q(4.01, 9.99)).is_none());
    assert!(scene.intersect1(&q(10.01, f32::INFINITY)).is_none());
    assert!(!scene.occluded1(&q(0.0, 3.99)));
    assert!(scene.occluded1(&q(0.0, 4.01)));
    assert!(!scene.occluded1(&q(10.01, f32::INFINITY)));
    // No back-face culling: from the other side the same faces are hit.
    let back = RayQuery {
        origin: Vec3::new(0.3, -0.2, 7.0),
        dir: -Vec3::Z,
        tnear: 0.0,
        tfar: f32::INFINITY,
    };
    let h = scene.intersect1(&back).unwrap();
    assert_close("back t", h.t, 2.0, 1e-6);
    assert!(h.prim_id >= 2);
    // The geometric normal is not flipped towards the ray: still +z.
    assert!(h.ng.normalize().abs_diff_eq(Vec3::Z, 1e-6), "ng {:?}", h.ng);
}

#[test]
fn closed_mesh_is_watertight_along_edges() {
    // An octahedron; rays through its shared edges and vertices must not leak (ROBUST).
    let dev = device();
    let v = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let f = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let mut b = dev.scene_builder();
    b.add_triangle_mesh(&v, &f).unwrap();
    let scene = b.commit().unwrap();
    let mut rng = Pcg32::new(4, 1);
    for _ in 0..10_000 {
        // A point exactly on an edge (or a vertex) and an interior point c (|x|+|y|+|z| <
        // 1/2). The line from c through the edge point crosses the surface only there.
        let e = f[(rng.next_u32() % 8) as usize];
        let k = (rng.next_u32() % 3) as usize;
        let s = if rng.f32() < 0.1 { 0.0 } else { rng.f32() };
        let edge = v[e[k] as usize].lerp(v[e[(k + 1) % 3] as usize], s);
        let c = loop {
            let c = rng.in_box(0.5);
            if c.abs().element_sum() < 0.5 {
                break c;
            }
        };
        let out = edge - c;
        // From outside, entering through the edge.
        let origin = edge + out * rng.range(0.5, 5.0);
        let q = ray(origin, c - origin);
        let h = scene.intersect1(&q);
        assert!(h.is_some(), "ray {q:?} leaked in through edge point {edge}");
        let want = origin.distance(edge) / (c - origin).length();
        assert!((h.unwrap().t - want).abs() < 1e-5, "{h:?}, want t = {want}");
        // From inside, leaving through the edge.
        let q = ray(c, out * rng.range(0.1, 2.0));
        assert!(
            scene.intersect1(&q).is_some(),
            "ray {q:?} leaked out through {edge}"
        );
        assert!(scene.occluded1(&q));
    }
}

// ---------------------------------------------------------------------------------------
// Mixed scenes: IDs, occlusion, packets, threads

/// Spheres and meshes with geometry IDs 0..n in insertion order.
fn mixed_scene(dev: &Device) -> Scene {
    let mut rng = Pcg32::new(5, 1);
    let mut b = dev.scene_builder();
    for i in 0..6u32 {
        let id = if i % 2 == 0 {
            b.add_sphere(rng.in_box(5.0), rng.range(1.0, 2.5)).unwrap()
        } else {
            let (p, idx) = random_triangles(&mut rng, 10);
            b.add_triangle_mesh(&p, &idx).unwrap()
        };
        assert_eq!(id, i);
    }
    assert_eq!(b.geometry_count(), 6);
    let scene = b.commit().unwrap();
    assert_eq!(scene.geometry_count(), 6);
    scene
}

fn random_query(rng: &mut Pcg32) -> RayQuery {
    let origin = rng.in_box(8.0);
    RayQuery {
        origin,
        dir: rng.unit() * rng.range(0.5, 2.0),
        tnear: rng.range(0.0, 0.5),
        tfar: if rng.f32() < 0.3 {
            f32::INFINITY
        } else {
            rng.range(1.0, 15.0)
        },
    }
}

#[test]
fn geometry_ids_follow_insertion_order() {
    let dev = device();
    let mut b = dev.scene_builder();
    // Spheres along x, alternating with single-triangle meshes along y.
    for i in 0..8u32 {
        let x = 4.0 * i as f32 + 4.0;
        let id = if i % 2 == 0 {
            b.add_sphere(Vec3::new(x, 0.0, 0.0), 1.0).unwrap()
        } else {
            let p = [
                Vec3::new(-1.0, x, -1.0),
                Vec3::new(1.0, x, -1.0),
                Vec3::new(0.0, x, 1.0),
            ];
            b.add_triangle_mesh(&p, &[[0, 1, 2]]).unwrap()
        };
        assert_eq!(id, i);
    }
    let scene = b.commit().unwrap();
    for i in 0..8u32 {
        let x = 4.0 * i as f32 + 4.0;
        let q = if i % 2 == 0 {
            // Down onto sphere i.
            ray(Vec3::new(x, 0.0, 10.0), -Vec3::Z)
        } else {
            // Along +y onto the triangle in the plane y = x.
            ray(Vec3::new(0.0, x - 2.0, -0.2), Vec3::Y)
        };
        let h = scene
            .intersect1(&q)
            .unwrap_or_else(|| panic!("geometry {i} missed"));
        assert_eq!(h.geom_id, i);
    }
}

#[test]
fn occlusion_agrees_with_intersection() {
    let dev = device();
    let scene = mixed_scene(&dev);
    let mut rng = Pcg32::new(6, 1);
    let mut occluded = 0;
    for _ in 0..20_000 {
        let q = random_query(&mut rng);
        let hit = scene.intersect1(&q);
        if let Some(h) = hit {
            // Embree promises nothing for hits at (or very near) the segment ends.
            let len = q.dir.length();
            if ((h.t - q.tfar) * len).abs() < 1e-3 || ((h.t - q.tnear) * len).abs() < 1e-3 {
                continue;
            }
        }
        assert_eq!(scene.occluded1(&q), hit.is_some(), "ray {q:?}, hit {hit:?}");
        assert_eq!(
            scene.occluded1_with(&q, RayCoherence::Coherent),
            hit.is_some()
        );
        assert_eq!(scene.intersect1_with(&q, RayCoherence::Coherent), hit);
        occluded += hit.is_some() as u32;
    }
    assert!(occluded > 1_000, "only {occluded} occluded rays");
}

#[test]
fn packets_agree_with_single_rays() {
    let dev = device();
    let scene = mixed_scene(&dev);
    let mut rng = Pcg32::new(7, 1);
    let mut active_lanes = 0;
    for n in 0..3_000 {
        let mut rays: [RayQuery; 8] = std::array::from_fn(|_| random_query(&mut rng));
        // Every 7th packet: one lane gets an invalid ray (NaN origin) although active.
        if n % 7 == 0 {
            rays[3].origin.x = f32::NAN;
        }
        let active = match n % 5 {
            0 => 0xff,
            1 => 0,
            _ => (rng.next_u32() & 0xff) as u8,
        };
        let hits = scene.intersect8(&rays, active);
        let occ = scene.occluded8(&rays, active);
        for i in 0..8 {
            if active & (1 << i) == 0 {
                assert_eq!(hits[i], None, "inactive lane {i} reported a hit");
                assert_eq!(occ & (1 << i), 0, "inactive lane {i} reported occlusion");
                continue;
            }
            active_lanes += 1;
            let single = scene.intersect1(&rays[i]);
            match (single, hits[i]) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    assert_eq!((a.geom_id, a.prim_id), (b.geom_id, b.prim_id));
                    assert!((a.t - b.t).abs() <= 1e-5 * a.t.max(1.0), "{a:?} vs {b:?}");
                    assert!(a.ng.abs_diff_eq(b.ng, 1e-4 * a.ng.length().max(1.0)));
                    assert!((a.u - b.u).abs() < 1e-5 && (a.v - b.v).abs() < 1e-5);
                }
                (a, b) => panic!("lane {i} ray {:?}: single {a:?}, packet {b:?}", rays[i]),
            }
            assert_eq!(
                occ & (1 << i) != 0,
                scene.occluded1(&rays[i]),
                "lane {i} ray {:?}",
                rays[i]
            );
        }
    }
    assert!(active_lanes > 10_000);
}

fn assert_same_hit(single: Option<Hit>, other: Option<Hit>, what: &str, ray: &RayQuery) {
    match (single, other) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            assert_eq!((a.geom_id, a.prim_id), (b.geom_id, b.prim_id), "{what}");
            assert!(
                (a.t - b.t).abs() <= 1e-5 * a.t.max(1.0),
                "{what}: {a:?} vs {b:?}"
            );
            assert!(
                a.ng.abs_diff_eq(b.ng, 1e-4 * a.ng.length().max(1.0)),
                "{what}"
            );
            assert!(
                (a.u - b.u).abs() < 1e-5 && (a.v - b.v).abs() < 1e-5,
                "{what}"
            );
        }
        (a, b) => panic!("{what}: ray {ray:?}: single {a:?}, other {b:?}"),
    }
}

/// The 4- and 16-wide packets (both coherence hints) and Embree 3's stream API find the
/// single-ray hits, and the 4-, 8- and 16-wide occlusion queries the single-ray
/// occlusion, with inactive and invalid lanes left out; on Embree 4 the stream reports
/// that it is unavailable.
#[test]
fn packets_of_4_and_16_and_streams_agree_with_single_rays() {
    let dev = device();
    let scene = mixed_scene(&dev);
    let mut rng = Pcg32::new(9, 1);
    let mut scratch = StreamScratch::default();
    for n in 0..500 {
        let mut rays: [RayQuery; 16] = std::array::from_fn(|_| random_query(&mut rng));
        if n % 7 == 0 {
            rays[5].origin.x = f32::NAN;
        }
        let active = match n % 5 {
            0 => 0xffff,
            1 => 0,
            _ => (rng.next_u32() & 0xffff) as u16,
        };
        let coherence = if n % 2 == 0 {
            RayCoherence::Coherent
        } else {
            RayCoherence::Incoherent
        };
        let h16 = scene.intersect16_with(&rays, active, coherence);
        let lo: [RayQuery; 4] = std::array::from_fn(|i| rays[i]);
        let h4 = scene.intersect4_with(&lo, (active & 0xf) as u8, coherence);
        let o16 = scene.occluded16_with(&rays, active, coherence);
        let o4 = scene.occluded4_with(&lo, (active & 0xf) as u8, coherence);
        let half: [RayQuery; 8] = std::array::from_fn(|i| rays[i]);
        let o8 = scene.occluded8_with(&half, (active & 0xff) as u8, coherence);
        let mut stream = [None; 16];
        let has_stream = scene.intersect_stream(&rays, coherence, &mut scratch, &mut stream);
        assert_eq!(has_stream, heron::accel::embree::BINDINGS_MAJOR == 3);
        for i in 0..16 {
            let single = scene.intersect1(&rays[i]);
            if has_stream {
                assert_same_hit(single, stream[i], "stream", &rays[i]);
            }
            if active & (1 << i) == 0 {
                assert_eq!(h16[i], None, "inactive lane {i} reported a hit");
                assert_eq!(o16 & (1 << i), 0, "inactive lane {i} reported occlusion");
                continue;
            }
            assert_same_hit(single, h16[i], "16-wide", &rays[i]);
            if i < 4 {
                assert_same_hit(single, h4[i], "4-wide", &rays[i]);
            }
            // Occlusion where the closest hit is clear of the segment's ends (Embree
            // promises nothing for hits at them).
            let clear = single.is_none_or(|h| {
                let len = rays[i].dir.length();
                ((h.t - rays[i].tfar) * len).abs() >= 1e-3
                    && ((h.t - rays[i].tnear) * len).abs() >= 1e-3
            });
            if clear {
                let occluded = scene.occluded1(&rays[i]);
                assert_eq!(o16 & (1 << i) != 0, occluded, "16-wide occlusion, lane {i}");
                if i < 8 {
                    assert_eq!(o8 & (1 << i) != 0, occluded, "8-wide occlusion, lane {i}");
                }
                if i < 4 {
                    assert_eq!(o4 & (1 << i) != 0, occluded, "4-wide occlusion, lane {i}");
                }
            }
        }
    }
}

#[test]
fn queries_from_many_threads_match_one_thread() {
    let dev = device();
    let scene = Arc::new(mixed_scene(&dev));
    drop(dev); // the committed scene keeps the device alive
    let mut rng = Pcg32::new(8, 1);
    let rays: Arc<Vec<RayQuery>> = Arc::new((0..8_000).map(|_| random_query(&mut rng)).collect());
    let reference: Vec<(Option<Hit>, bool)> = rays
        .iter()
        .map(|q| (scene.intersect1(q), scene.occluded1(q)))
        .collect();
    let threads: Vec<_> = (0..4)
        .map(|k| {
            let scene = Arc::clone(&scene);
            let rays = Arc::clone(&rays);
            std::thread::spawn(move || {
                // Each thread walks the rays in a different order (a permutation: the
                // stride is coprime with n = 8000).
                let n = rays.len();
                let stride = [1, 3, 7, 11][k];
                let mut out = vec![(None, false); n];
                for j in 0..n {
                    let i = (j * stride + k * 977) % n;
                    out[i] = (scene.intersect1(&rays[i]), scene.occluded1(&rays[i]));
                }
                let packets: Vec<[Option<Hit>; 8]> = rays
                    .chunks_exact(8)
                    .map(|c| scene.intersect8(c.try_into().unwrap(), 0xff))
                    .collect();
                (out, packets)
            })
        })
        .collect();
    for t in threads {
        let (out, packets) = t.join().expect("query thread panicked");
        for (i, (got, want)) in out.iter().zip(&reference).enumerate() {
            assert_eq!(got, want, "ray {i}: {:?}", rays[i]);
        }
        for (c, p) in reference.chunks_exact(8).zip(&packets) {
            for (r, h) in c.iter().zip(p) {
                assert_eq!(
                    r.0.map(|h| (h.geom_id, h.prim_id)),
                    h.map(|h| (h.geom_id, h.prim_id))
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Edge cases and errors

#[test]
fn invalid_rays_give_no_hit() {
    let dev = device();
    let mut b = dev.scene_builder();
    b.add_sphere(Vec3::ZERO, 1.0).unwrap();
    let scene = b.commit().unwrap();
    let good = ray(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
    assert!(scene.intersect1(&good).is_some());
    let bad = [
        RayQuery {
            origin: Vec3::NAN,
            ..good
        },
        RayQuery {
            dir: Vec3::new(0.0, f32::INFINITY, 1.0),
            ..good
        },
        RayQuery {
            dir: Vec3::ZERO,
            ..good
        },
        RayQuery {
            tnear: -1.0,
            ..good
        },
        RayQuery {
            tnear: f32::NAN,
            ..good
        },
        RayQuery {
            tfar: f32::NAN,
            ..good
        },
        RayQuery {
            tnear: 3.0,
            tfar: 2.0,
            ..good
        },
    ];
    assert!(good.is_valid());
    for q in &bad {
        assert!(!q.is_valid(), "{q:?}");
        assert_eq!(scene.intersect1(q), None, "{q:?}");
        assert!(!scene.occluded1(q), "{q:?}");
    }
    // Edge cases the vector check must agree on: tnear = tfar, -0 tnear, infinite tfar,
    // a direction with one non-zero component (valid); infinite tnear (not).
    let edge = [
        (
            RayQuery {
                tnear: 2.0,
                tfar: 2.0,
                ..good
            },
            true,
        ),
        (
            RayQuery {
                tnear: -0.0,
                ..good
            },
            true,
        ),
        (
            RayQuery {
                dir: Vec3::new(0.0, 0.0, 1e-30),
                ..good
            },
            true,
        ),
        (
            RayQuery {
                tnear: f32::INFINITY,
                tfar: f32::INFINITY,
                ..good
            },
            false,
        ),
    ];
    for (q, valid) in edge {
        assert_eq!(q.is_valid(), valid, "{q:?}");
        let lanes = [q; 4];
        // An invalid ray is never traced: not occluded.
        if !valid {
            assert_eq!(
                scene.occluded4_with(&lanes, 0xf, RayCoherence::Incoherent),
                0
            );
            assert!(!scene.occluded1(&q));
        }
    }
    // A tnear of -0 is 0: traced, and it hits, singly and in every lane.
    let q = RayQuery {
        tnear: -0.0,
        ..good
    };
    assert!(scene.intersect1(&q).is_some());
    let h = scene.intersect4_with(&[q; 4], 0xf, RayCoherence::Incoherent);
    assert!(h.iter().all(Option::is_some), "{h:?}");
    let mut rays = [good; 8];
    rays[..7].copy_from_slice(&bad);
    let hits = scene.intersect8(&rays, 0xff);
    assert!(hits[..7].iter().all(Option::is_none));
    assert!(hits[7].is_some());
    assert_eq!(scene.occluded8(&rays, 0xff), 0x80);
    // Every width: each bad ray in every lane position (the packets test four lanes at a
    // time), beside good rays, and the stream.
    let mut scratch = StreamScratch::default();
    for (k, q) in bad.iter().enumerate() {
        for lane in 0..16 {
            let mut r16 = [good; 16];
            r16[lane] = *q;
            let want: u16 = !(1 << lane);
            let h16 = scene.intersect16_with(&r16, 0xffff, RayCoherence::Incoherent);
            let got = (0..16).fold(0u16, |m, i| m | ((h16[i].is_some() as u16) << i));
            assert_eq!(got, want, "bad ray {k} in lane {lane} of 16");
            assert_eq!(
                scene.occluded16_with(&r16, 0xffff, RayCoherence::Coherent),
                want,
                "bad ray {k} in lane {lane} of 16 (occlusion)"
            );
            if lane < 4 {
                let r4: [RayQuery; 4] = std::array::from_fn(|i| r16[i]);
                let h4 = scene.intersect4_with(&r4, 0xf, RayCoherence::Incoherent);
                let got = (0..4).fold(0u8, |m, i| m | ((h4[i].is_some() as u8) << i));
                assert_eq!(got, want as u8 & 0xf, "bad ray {k} in lane {lane} of 4");
                assert_eq!(
                    scene.occluded4_with(&r4, 0xf, RayCoherence::Incoherent),
                    want as u8 & 0xf
                );
            }
            let mut stream = [None; 16];
            if scene.intersect_stream(&r16, RayCoherence::Incoherent, &mut scratch, &mut stream) {
                let got = (0..16).fold(0u16, |m, i| m | ((stream[i].is_some() as u16) << i));
                assert_eq!(got, want, "bad ray {k} at {lane} of a stream");
            }
        }
    }
}

#[test]
fn bad_geometry_is_an_error_not_a_panic() {
    let dev = device();
    let mut b = dev.scene_builder();
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let is_other = |r: Result<u32, EmbreeError>, what: &str| match r {
        Err(EmbreeError::Other(m)) => eprintln!("{what}: {m}"),
        other => panic!("{what}: expected Err(Other), got {other:?}"),
    };
    is_other(
        b.add_triangle_mesh(
            &[Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y],
            &[[0, 1, 2]],
        ),
        "NaN vertex",
    );
    is_other(
        b.add_triangle_mesh(
            &[Vec3::ZERO, Vec3::X, Vec3::splat(f32::INFINITY)],
            &[[0, 1, 2]],
        ),
        "infinite vertex",
    );
    is_other(
        b.add_triangle_mesh(&[Vec3::ZERO, Vec3::X, Vec3::splat(1e19)], &[[0, 1, 2]]),
        "vertex beyond Embree's range",
    );
    is_other(
        b.add_triangle_mesh(&tri, &[[0, 1, 3]]),
        "index out of range",
    );
    is_other(
        b.add_triangle_mesh(&tri, &[[0, 1, u32::MAX]]),
        "index u32::MAX",
    );
    is_other(b.add_triangle_mesh(&tri, &[]), "no triangles");
    is_other(b.add_triangle_mesh(&[], &[[0, 0, 0]]), "no vertices");
    is_other(b.add_sphere(Vec3::ZERO, -1.0), "negative radius");
    is_other(b.add_sphere(Vec3::ZERO, 0.0), "zero radius");
    is_other(b.add_sphere(Vec3::ZERO, f32::NAN), "NaN radius");
    is_other(b.add_sphere(Vec3::ZERO, f32::INFINITY), "infinite radius");
    is_other(
        b.add_sphere(Vec3::new(0.0, f32::NAN, 0.0), 1.0),
        "NaN centre",
    );
    // Rejected input consumed no geometry ID: the builder carries on from 0.
    assert_eq!(b.add_triangle_mesh(&tri, &[[0, 1, 2]]).unwrap(), 0);
    assert_eq!(b.add_sphere(Vec3::splat(5.0), 1.0).unwrap(), 1);
    let scene = b.commit().unwrap();
    assert_eq!(scene.geometry_count(), 2);
    let h = scene
        .intersect1(&ray(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z))
        .unwrap();
    assert_eq!(h.geom_id, 0);
}

#[test]
fn device_errors_are_reported() {
    // Embree 3 rejects a non-numeric thread count: rtcNewDevice returns NULL.
    match Device::new("threads=abc") {
        Err(EmbreeError::Device { code, message }) => {
            assert!(code.starts_with("RTC_ERROR_"), "{code}");
            assert!(message.contains("rtcNewDevice"), "{message}");
        }
        other => panic!("expected a device error, got {other:?}"),
    }
    assert!(matches!(
        Device::new("threads=1\0"),
        Err(EmbreeError::Other(_))
    ));
    let dev = Device::new("threads=1").unwrap();
    let (major, _, _) = dev.version();
    assert_eq!(
        major,
        heron::accel::embree::BINDINGS_MAJOR,
        "the linked Embree's version differs from the one the bindings were built for"
    );
}

#[test]
fn empty_scene_and_bounds() {
    let dev = device();
    let empty = dev.scene_builder().commit().unwrap();
    assert_eq!(empty.geometry_count(), 0);
    assert_eq!(empty.bounds(), None);
    let q = ray(Vec3::ZERO, Vec3::X);
    assert_eq!(empty.intersect1(&q), None);
    assert!(!empty.occluded1(&q));
    assert_eq!(empty.intersect8(&[q; 8], 0xff), [None; 8]);
    assert_eq!(empty.occluded8(&[q; 8], 0xff), 0);

    // A builder dropped without commit releases its scene (no leak, no crash).
    let mut b = dev.scene_builder();
    b.add_sphere(Vec3::ZERO, 1.0).unwrap();
    drop(b);

    let mut b = dev.scene_builder();
    b.add_sphere(Vec3::new(1.0, 2.0, 3.0), 0.5).unwrap();
    b.add_triangle_mesh(
        &[
            Vec3::new(-4.0, 0.0, 0.0),
            Vec3::new(0.0, 5.0, 0.0),
            Vec3::new(0.0, 0.0, 6.0),
        ],
        &[[0, 1, 2]],
    )
    .unwrap();
    let scene = b.commit().unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    assert!(lo.cmple(Vec3::new(-4.0, 0.0, 0.0)).all(), "{lo}");
    assert!(hi.cmpge(Vec3::new(1.5, 5.0, 6.0)).all(), "{hi}");
    assert!(lo.cmpge(Vec3::splat(-4.1)).all() && hi.cmple(Vec3::splat(6.1)).all());
}

#[test]
fn scene_outlives_device_and_moves_between_threads() {
    let scene = {
        let dev = device();
        let mut b = dev.scene_builder();
        b.add_sphere(Vec3::ZERO, 1.0).unwrap();
        b.commit().unwrap()
    };
    struct Holder {
        scene: Scene,
    }
    let holder = Holder { scene };
    let t = std::thread::spawn(move || {
        holder
            .scene
            .intersect1(&ray(Vec3::new(0.0, 0.0, -3.0), Vec3::Z))
            .map(|h| h.t)
    });
    let t = t.join().unwrap().unwrap();
    assert!((t - 2.0).abs() < 1e-6);
}

#[test]
fn worker_pool_threads_flush_denormals() {
    // A fresh thread starts with the default MXCSR (no FTZ/DAZ) …
    std::thread::spawn(|| {
        let tiny = std::hint::black_box(f32::MIN_POSITIVE);
        assert!(!flush_denormals_enabled());
        assert!(
            tiny * std::hint::black_box(0.5f32) > 0.0,
            "denormal result expected"
        );
    })
    .join()
    .unwrap();
    // … and heron's workers have both bits set.
    let pool = worker_pool(2).unwrap();
    let results: Vec<(bool, f32, f32)> = pool.broadcast(|_| {
        let tiny = std::hint::black_box(f32::MIN_POSITIVE);
        let denormal = std::hint::black_box(f32::from_bits(1));
        (
            flush_denormals_enabled(),
            tiny * std::hint::black_box(0.5f32),
            denormal * std::hint::black_box(1.0f32),
        )
    });
    for (enabled, ftz, daz) in results {
        if cfg!(target_arch = "x86_64") {
            assert!(enabled);
            assert_eq!(ftz, 0.0, "FTZ: a denormal result flushes to zero");
            assert_eq!(daz, 0.0, "DAZ: a denormal input reads as zero");
        }
    }
}
