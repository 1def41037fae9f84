//! The scene at t = 0 as placed objects, and ray tracing through it.

use super::description::{ObjectDescription, SceneDescription};
use super::shapes::{Segment, Shape, branch_segments};
use super::texture::{Rgb, Texture};
use nalgebra::{Point3, Rotation3, Vector3};

/// An object placed in the scene.
#[derive(Debug, Clone)]
struct Placed {
    shape: Shape,
    /// Local to scene rotation.
    rotation: Rotation3<f64>,
    position: Point3<f64>,
    texture: Texture,
    segments: Vec<Segment>,
    bound: f64,
}

/// A ray's first hit in the scene.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Ray parameter.
    pub t: f64,
    /// The point hit, in the scene's frame at t = 0.
    pub point: Point3<f64>,
    /// Its shaded colour.
    pub color: Rgb,
}

/// The objects of a scene, ready to be traced.
#[derive(Debug, Clone)]
pub struct World {
    objects: Vec<Placed>,
    /// Colour where a ray meets nothing.
    pub background: Rgb,
}

/// Direction towards the light, fixed to the scene (so shading moves with it, as albedo does).
fn light() -> Vector3<f64> {
    Vector3::new(0.35, -0.6, -0.72).normalize()
}

impl World {
    /// Places the objects of `desc`; `seed` is mixed into every texture and shape seed.
    pub fn new(desc: &SceneDescription, seed: u64) -> Self {
        let objects = desc
            .objects
            .iter()
            .map(|o: &ObjectDescription| {
                let [rx, ry, rz] = o.rotation_deg.map(f64::to_radians);
                let rotation = Rotation3::from_axis_angle(&Vector3::z_axis(), rz)
                    * Rotation3::from_axis_angle(&Vector3::y_axis(), ry)
                    * Rotation3::from_axis_angle(&Vector3::x_axis(), rx);
                let mut texture = o.texture.clone();
                if let Texture::Noise { seed: s, .. } = &mut texture {
                    *s ^= seed;
                }
                let segments = match &o.shape {
                    Shape::Branches { count, extent, seed: s, .. } => branch_segments(*count, *extent, s ^ seed),
                    _ => Vec::new(),
                };
                Placed {
                    bound: o.shape.bounding_radius(),
                    shape: o.shape.clone(),
                    rotation,
                    position: Point3::from(o.position),
                    texture,
                    segments,
                }
            })
            .collect();
        Self { objects, background: desc.background }
    }

    /// The first hit of the ray `o + t d` (scene frame at t = 0), if any.
    pub fn trace(&self, o: &Point3<f64>, d: &Vector3<f64>) -> Option<Hit> {
        let mut best: Option<(f64, usize, Vector3<f64>, Point3<f64>)> = None;
        let d2 = d.norm_squared();
        for (i, obj) in self.objects.iter().enumerate() {
            // Bounding sphere: skip objects the ray misses or that lie beyond the best hit.
            let oc = o - obj.position;
            let b = oc.dot(d);
            let c = oc.norm_squared() - obj.bound * obj.bound;
            let disc = b * b - d2 * c;
            if disc < 0.0 {
                continue;
            }
            let t_enter = (-b - disc.sqrt()) / d2;
            if best.is_some_and(|(t, ..)| t_enter > t) {
                continue;
            }
            let inv = obj.rotation.inverse();
            let ol = Point3::from(inv * oc);
            let dl = inv * d;
            if let Some(h) = obj.shape.intersect(&ol, &dl, &obj.segments)
                && best.is_none_or(|(t, ..)| h.t < t)
            {
                best = Some((h.t, i, h.normal, ol + dl * h.t));
            }
        }
        let (t, i, normal, local) = best?;
        let obj = &self.objects[i];
        let n = (obj.rotation * normal).try_normalize(1e-12).unwrap_or_else(Vector3::z);
        let shade = 0.6 + 0.4 * n.dot(&light()).abs();
        let albedo = obj.texture.color(&local);
        Some(Hit { t, point: o + d * t, color: albedo.map(|a| (a * shade).clamp(0.0, 1.0)) })
    }
}
