//! Analytic primitives in their own frame, and where a ray first meets them.
//!
//! Rays are `o + t d` with `d` not necessarily unit; the returned `t` is in those units, so it
//! stays valid after the rigid transform that placed the object.

use crate::random::Rng;
use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

/// A primitive, described in its own frame (centred on its origin).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Shape {
    /// A rectangle in the local XY plane.
    Rectangle {
        /// Width (X) and height (Y), metres.
        size: [f64; 2],
    },
    /// A box with these full extents along X, Y, Z.
    Box {
        /// Extents, metres.
        size: [f64; 3],
    },
    /// A sphere.
    Sphere {
        /// Radius, metres.
        radius: f64,
    },
    /// A capped cylinder along the local Y axis.
    Cylinder {
        /// Radius, metres.
        radius: f64,
        /// Height, metres.
        height: f64,
    },
    /// A lattice of bars in the local XY plane (a fence, a grille): thin structures with holes.
    Grid {
        /// Width and height, metres.
        size: [f64; 2],
        /// Width of a bar, metres.
        bar_width: f64,
        /// Distance between bars, metres.
        spacing: f64,
    },
    /// A random tree of thin cylinders inside a box of `extent` (vegetation, branches).
    Branches {
        /// Number of branch segments.
        count: usize,
        /// Radius of a branch, metres.
        radius: f64,
        /// Extents of the box holding the tree, metres.
        extent: [f64; 3],
        /// Seed of the tree's shape.
        #[serde(default)]
        seed: u64,
    },
}

/// A ray's first hit on a shape: distance parameter and local surface normal.
#[derive(Debug, Clone, Copy)]
pub struct LocalHit {
    /// Ray parameter of the hit.
    pub t: f64,
    /// Surface normal in the shape's frame (not necessarily facing the ray).
    pub normal: Vector3<f64>,
}

/// A segment of a `Branches` tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start point.
    pub a: Point3<f64>,
    /// End point.
    pub b: Point3<f64>,
}

/// The segments of a `Branches` shape: a trunk from the bottom (local +Y, down in the camera)
/// splitting into two or three branches at each level, all inside `extent`.
pub fn branch_segments(count: usize, extent: [f64; 3], seed: u64) -> Vec<Segment> {
    let mut rng = Rng::new(seed);
    let half = Vector3::from(extent) * 0.5;
    let clamp = |p: Point3<f64>| Point3::new(p.x.clamp(-half.x, half.x), p.y.clamp(-half.y, half.y), p.z.clamp(-half.z, half.z));
    let mut segments = Vec::with_capacity(count);
    let mut tips = vec![(Point3::new(0.0, half.y, 0.0), Vector3::new(0.0, -1.0, 0.0), extent[1] * 0.35)];
    while segments.len() < count && !tips.is_empty() {
        let mut next = Vec::new();
        for (start, dir, length) in tips {
            if segments.len() >= count {
                break;
            }
            let end = clamp(start + dir * length);
            segments.push(Segment { a: start, b: end });
            let children = 2 + usize::from(rng.unit() < 0.5);
            for _ in 0..children {
                let jitter = Vector3::new(rng.range(-0.9, 0.9), rng.range(-0.5, 0.2), rng.range(-0.6, 0.6));
                let d = (dir + jitter).try_normalize(1e-9).unwrap_or(dir);
                next.push((end, d, length * rng.range(0.55, 0.8)));
            }
        }
        tips = next;
    }
    segments
}

fn rectangle_t(o: &Point3<f64>, d: &Vector3<f64>) -> Option<(f64, f64, f64)> {
    if d.z.abs() < 1e-15 {
        return None;
    }
    let t = -o.z / d.z;
    (t > 0.0).then(|| (t, o.x + t * d.x, o.y + t * d.y))
}

fn sphere_t(o: &Vector3<f64>, d: &Vector3<f64>, r: f64) -> Option<f64> {
    let a = d.norm_squared();
    let b = o.dot(d);
    let c = o.norm_squared() - r * r;
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    [(-b - s) / a, (-b + s) / a].into_iter().find(|&t| t > 1e-9)
}

/// Nearest hit with the side of a cylinder of radius `r` around the segment `a + s (b - a)`, s in [0, 1].
fn segment_cylinder_t(o: &Point3<f64>, d: &Vector3<f64>, seg: &Segment, r: f64) -> Option<LocalHit> {
    let axis = seg.b - seg.a;
    let len2 = axis.norm_squared();
    if len2 < 1e-18 {
        return None;
    }
    let w = o - seg.a;
    let (dd, da, wa) = (d.dot(&axis) / len2, d, w.dot(&axis) / len2);
    let dp = da - axis * dd; // components perpendicular to the axis
    let wp = w - axis * wa;
    let a = dp.norm_squared();
    if a < 1e-18 {
        return None;
    }
    let b = wp.dot(&dp);
    let c = wp.norm_squared() - r * r;
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    for t in [(-b - s) / a, (-b + s) / a] {
        let along = wa + t * dd;
        if t > 1e-9 && (0.0..=1.0).contains(&along) {
            return Some(LocalHit { t, normal: wp + dp * t });
        }
    }
    None
}

impl Shape {
    /// The first hit of the ray `o + t d` (t > 0), in the shape's frame.
    pub fn intersect(&self, o: &Point3<f64>, d: &Vector3<f64>, segments: &[Segment]) -> Option<LocalHit> {
        match self {
            Shape::Rectangle { size } => {
                let (t, x, y) = rectangle_t(o, d)?;
                (x.abs() <= size[0] / 2.0 && y.abs() <= size[1] / 2.0).then_some(LocalHit { t, normal: Vector3::z() })
            }
            Shape::Grid { size, bar_width, spacing } => {
                let (t, x, y) = rectangle_t(o, d)?;
                if x.abs() > size[0] / 2.0 || y.abs() > size[1] / 2.0 {
                    return None;
                }
                let on_bar = |v: f64, extent: f64| (v + extent / 2.0).rem_euclid(*spacing) < *bar_width;
                (on_bar(x, size[0]) || on_bar(y, size[1])).then_some(LocalHit { t, normal: Vector3::z() })
            }
            Shape::Sphere { radius } => {
                let t = sphere_t(&o.coords, d, *radius)?;
                Some(LocalHit { t, normal: o.coords + d * t })
            }
            Shape::Box { size } => {
                let half = Vector3::from(*size) * 0.5;
                let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
                let (mut axis0, mut axis1) = (0, 0);
                for i in 0..3 {
                    if d[i].abs() < 1e-15 {
                        if o[i].abs() > half[i] {
                            return None;
                        }
                        continue;
                    }
                    let (mut a, mut b) = ((-half[i] - o[i]) / d[i], (half[i] - o[i]) / d[i]);
                    if a > b {
                        std::mem::swap(&mut a, &mut b);
                    }
                    if a > t0 {
                        t0 = a;
                        axis0 = i;
                    }
                    if b < t1 {
                        t1 = b;
                        axis1 = i;
                    }
                }
                if t0 > t1 || t1 <= 1e-9 {
                    return None;
                }
                let (t, axis) = if t0 > 1e-9 { (t0, axis0) } else { (t1, axis1) };
                let mut normal = Vector3::zeros();
                normal[axis] = 1.0;
                Some(LocalHit { t, normal })
            }
            Shape::Cylinder { radius, height } => {
                let h = height / 2.0;
                let side = segment_cylinder_t(o, d, &Segment { a: Point3::new(0.0, -h, 0.0), b: Point3::new(0.0, h, 0.0) }, *radius);
                let caps = [-h, h].into_iter().filter_map(|y| {
                    if d.y.abs() < 1e-15 {
                        return None;
                    }
                    let t = (y - o.y) / d.y;
                    let p = o + d * t;
                    (t > 1e-9 && p.x * p.x + p.z * p.z <= radius * radius).then_some(LocalHit { t, normal: Vector3::y() })
                });
                side.into_iter().chain(caps).min_by(|a, b| a.t.total_cmp(&b.t))
            }
            Shape::Branches { radius, .. } => {
                let d2 = d.norm_squared();
                segments
                    .iter()
                    .filter(|s| {
                        // Cheap rejection: the ray must pass the segment's bounding sphere.
                        let centre = Point3::from((s.a.coords + s.b.coords) * 0.5);
                        let bound = (s.b - s.a).norm() * 0.5 + radius;
                        let oc = o - centre;
                        let b = oc.dot(d);
                        b * b - d2 * (oc.norm_squared() - bound * bound) >= 0.0
                    })
                    .filter_map(|s| segment_cylinder_t(o, d, s, *radius))
                    .min_by(|a, b| a.t.total_cmp(&b.t))
            }
        }
    }

    /// Radius of a sphere around the origin that holds the whole shape.
    pub fn bounding_radius(&self) -> f64 {
        let v = |x: &[f64]| x.iter().map(|a| a * a / 4.0).sum::<f64>().sqrt();
        match self {
            Shape::Rectangle { size } | Shape::Grid { size, .. } => v(size),
            Shape::Box { size } => v(size),
            Shape::Sphere { radius } => *radius,
            Shape::Cylinder { radius, height } => (radius * radius + height * height / 4.0).sqrt(),
            Shape::Branches { extent, radius, .. } => v(extent) + radius,
        }
    }

    /// Checks the parameters; the error names the field.
    pub fn validate(&self) -> Result<(), String> {
        let pos = |name: &str, v: f64| if v > 0.0 && v.is_finite() { Ok(()) } else { Err(format!("shape `{name}` must be positive")) };
        match self {
            Shape::Rectangle { size } => size.iter().try_for_each(|&v| pos("size", v)),
            Shape::Box { size } => size.iter().try_for_each(|&v| pos("size", v)),
            Shape::Sphere { radius } => pos("radius", *radius),
            Shape::Cylinder { radius, height } => pos("radius", *radius).and(pos("height", *height)),
            Shape::Grid { size, bar_width, spacing } => {
                size.iter().try_for_each(|&v| pos("size", v))?;
                pos("bar_width", *bar_width)?;
                pos("spacing", *spacing)?;
                if bar_width >= spacing { Err("shape `bar_width` must be below `spacing`".into()) } else { Ok(()) }
            }
            Shape::Branches { count, radius, extent, .. } => {
                if *count == 0 {
                    return Err("shape `count` must be at least 1".into());
                }
                pos("radius", *radius)?;
                extent.iter().try_for_each(|&v| pos("extent", v))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(shape: &Shape, o: [f64; 3], d: [f64; 3]) -> Option<f64> {
        let segs = match shape {
            Shape::Branches { count, extent, seed, .. } => branch_segments(*count, *extent, *seed),
            _ => vec![],
        };
        shape.intersect(&Point3::from(o), &Vector3::from(d), &segs).map(|h| h.t)
    }

    #[test]
    fn rays_from_the_front_hit_each_shape_at_its_near_surface() {
        let o = [0.0, 0.0, -5.0];
        let d = [0.0, 0.0, 1.0];
        assert_eq!(hit(&Shape::Rectangle { size: [1.0, 1.0] }, o, d), Some(5.0));
        assert_eq!(hit(&Shape::Sphere { radius: 1.0 }, o, d), Some(4.0));
        assert_eq!(hit(&Shape::Box { size: [2.0, 2.0, 2.0] }, o, d), Some(4.0));
        assert!((hit(&Shape::Cylinder { radius: 0.5, height: 2.0 }, o, d).unwrap() - 4.5).abs() < 1e-12);
        assert_eq!(hit(&Shape::Rectangle { size: [1.0, 1.0] }, [2.0, 0.0, -5.0], d), None);
        // A grid's hole lets the ray through; its bar stops it.
        let grid = Shape::Grid { size: [4.0, 4.0], bar_width: 0.1, spacing: 1.0 };
        assert_eq!(hit(&grid, [0.5, 0.5, -5.0], d), None);
        assert_eq!(hit(&grid, [0.05 - 2.0, 0.5, -5.0], d), Some(5.0));
    }

    #[test]
    fn a_ray_from_inside_a_box_exits_through_the_far_face() {
        assert_eq!(hit(&Shape::Box { size: [2.0, 2.0, 2.0] }, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), Some(1.0));
    }

    #[test]
    fn branches_stay_inside_their_extent_and_can_be_hit() {
        let segs = branch_segments(40, [2.0, 3.0, 1.0], 5);
        assert_eq!(segs.len(), 40);
        assert!(segs.iter().all(|s| s.b.x.abs() <= 1.0 && s.b.y.abs() <= 1.5 && s.b.z.abs() <= 0.5));
        let trunk = Shape::Branches { count: 40, radius: 0.05, extent: [2.0, 3.0, 1.0], seed: 5 };
        assert!(hit(&trunk, [0.0, 1.3, -5.0], [0.0, 0.0, 1.0]).is_some(), "the trunk rises from the bottom centre");
    }
}
