//! `motion.toml` / `gt_motion.toml`: a rigid motion of the scene in the central camera frame at
//! t = 0, in seconds, radians and metres.

use super::atomic::write_atomic;
use super::error::{IoError, IoResult};
use serde::Deserialize;
use std::path::Path;

/// A motion as its file states it. The model names and fields are those of the format.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionRecord {
    /// `P(t) = R(t ω) P0 + t v`.
    ConstantVelocity {
        /// Angular velocity ω, rad/s.
        omega_rad_s: [f64; 3],
        /// Linear velocity v, m/s.
        velocity_m_s: [f64; 3],
    },
    /// `P(t) = R(t ω + t²/2 α) P0 + t v + t²/2 a`.
    ConstantAcceleration {
        /// Angular velocity ω at t = 0, rad/s.
        omega_rad_s: [f64; 3],
        /// Linear velocity v at t = 0, m/s.
        velocity_m_s: [f64; 3],
        /// Angular acceleration α, rad/s².
        alpha_rad_s2: [f64; 3],
        /// Linear acceleration a, m/s².
        accel_m_s2: [f64; 3],
    },
    /// The read-out interval cut into equal segments, each with its own (ω_k, v_k).
    PiecewiseConstant {
        /// ω_k per segment, rad/s.
        omega_rad_s: Vec<[f64; 3]>,
        /// v_k per segment, m/s.
        velocity_m_s: Vec<[f64; 3]>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMotion {
    model: String,
    omega_rad_s: toml::Value,
    velocity_m_s: toml::Value,
    alpha_rad_s2: Option<toml::Value>,
    accel_m_s2: Option<toml::Value>,
    segments: Option<usize>,
}

fn vec3(key: &str, v: &toml::Value) -> Result<[f64; 3], String> {
    let items = v.as_array().ok_or_else(|| format!("`{key}` must be an array of 3 numbers"))?;
    let nums: Vec<f64> = items
        .iter()
        .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("`{key}` must be an array of 3 numbers"))?;
    match nums.as_slice() {
        [a, b, c] if nums.iter().all(|x| x.is_finite()) => Ok([*a, *b, *c]),
        _ => Err(format!("`{key}` must be an array of 3 finite numbers, found {}", nums.len())),
    }
}

fn vec3_list(key: &str, v: &toml::Value) -> Result<Vec<[f64; 3]>, String> {
    let items = v.as_array().ok_or_else(|| format!("`{key}` must be an array of [x, y, z] arrays"))?;
    items.iter().map(|x| vec3(key, x)).collect()
}

impl MotionRecord {
    /// The model name as the file writes it.
    pub fn model_name(&self) -> &'static str {
        match self {
            Self::ConstantVelocity { .. } => "constant_velocity",
            Self::ConstantAcceleration { .. } => "constant_acceleration",
            Self::PiecewiseConstant { .. } => "piecewise_constant",
        }
    }

    /// A motion of zero: a static scene.
    pub fn zero() -> Self {
        Self::ConstantVelocity { omega_rad_s: [0.0; 3], velocity_m_s: [0.0; 3] }
    }

    /// Parses the file's text; the error names the key and what was expected.
    pub fn parse(text: &str) -> Result<Self, String> {
        let raw: RawMotion = toml::from_str(text).map_err(|e| e.message().to_string())?;
        let extra = |key: &str, present: bool| {
            if present { Err(format!("`{key}` does not belong to model `{}`", raw.model)) } else { Ok(()) }
        };
        match raw.model.as_str() {
            "constant_velocity" => {
                extra("alpha_rad_s2", raw.alpha_rad_s2.is_some())?;
                extra("accel_m_s2", raw.accel_m_s2.is_some())?;
                extra("segments", raw.segments.is_some())?;
                Ok(Self::ConstantVelocity {
                    omega_rad_s: vec3("omega_rad_s", &raw.omega_rad_s)?,
                    velocity_m_s: vec3("velocity_m_s", &raw.velocity_m_s)?,
                })
            }
            "constant_acceleration" => {
                extra("segments", raw.segments.is_some())?;
                let need =
                    |key: &str, v: &Option<toml::Value>| v.as_ref().ok_or_else(|| format!("`{key}` is missing")).and_then(|v| vec3(key, v));
                Ok(Self::ConstantAcceleration {
                    omega_rad_s: vec3("omega_rad_s", &raw.omega_rad_s)?,
                    velocity_m_s: vec3("velocity_m_s", &raw.velocity_m_s)?,
                    alpha_rad_s2: need("alpha_rad_s2", &raw.alpha_rad_s2)?,
                    accel_m_s2: need("accel_m_s2", &raw.accel_m_s2)?,
                })
            }
            "piecewise_constant" => {
                extra("alpha_rad_s2", raw.alpha_rad_s2.is_some())?;
                extra("accel_m_s2", raw.accel_m_s2.is_some())?;
                let segments = raw.segments.ok_or("`segments` is missing")?;
                let omega = vec3_list("omega_rad_s", &raw.omega_rad_s)?;
                let velocity = vec3_list("velocity_m_s", &raw.velocity_m_s)?;
                if segments == 0 || omega.len() != segments || velocity.len() != segments {
                    return Err(format!(
                        "`segments = {segments}` needs that many omega_rad_s and velocity_m_s entries (found {} and {})",
                        omega.len(),
                        velocity.len()
                    ));
                }
                Ok(Self::PiecewiseConstant { omega_rad_s: omega, velocity_m_s: velocity })
            }
            other => Err(format!("unknown model `{other}` (expected constant_velocity, constant_acceleration or piecewise_constant)")),
        }
    }

    /// Reads a motion file.
    pub fn read(path: &Path) -> IoResult<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
        Self::parse(&text).map_err(|p| IoError::new(path, p))
    }

    /// The file's text.
    pub fn to_toml_string(&self) -> String {
        let v = |x: &[f64; 3]| format!("[{:e}, {:e}, {:e}]", x[0], x[1], x[2]);
        let list = |xs: &[[f64; 3]]| format!("[{}]", xs.iter().map(v).collect::<Vec<_>>().join(", "));
        let mut s = format!("model = \"{}\"\n", self.model_name());
        match self {
            Self::ConstantVelocity { omega_rad_s, velocity_m_s } => {
                s += &format!("omega_rad_s = {}\nvelocity_m_s = {}\n", v(omega_rad_s), v(velocity_m_s));
            }
            Self::ConstantAcceleration { omega_rad_s, velocity_m_s, alpha_rad_s2, accel_m_s2 } => {
                s += &format!(
                    "omega_rad_s = {}\nvelocity_m_s = {}\nalpha_rad_s2 = {}\naccel_m_s2 = {}\n",
                    v(omega_rad_s),
                    v(velocity_m_s),
                    v(alpha_rad_s2),
                    v(accel_m_s2)
                );
            }
            Self::PiecewiseConstant { omega_rad_s, velocity_m_s } => {
                s += &format!(
                    "segments = {}\nomega_rad_s = {}\nvelocity_m_s = {}\n",
                    omega_rad_s.len(),
                    list(omega_rad_s),
                    list(velocity_m_s)
                );
            }
        }
        s
    }

    /// Writes a motion file, whole or not at all.
    pub fn write(&self, path: &Path) -> IoResult<()> {
        write_atomic(path, self.to_toml_string().as_bytes())
    }

    /// The parameters as named groups of numbers, for comparing two motions of one model.
    pub fn groups(&self) -> Vec<(&'static str, Vec<f64>)> {
        let flat = |xs: &[[f64; 3]]| xs.iter().flatten().copied().collect::<Vec<_>>();
        match self {
            Self::ConstantVelocity { omega_rad_s, velocity_m_s } => {
                vec![("omega_rad_s", omega_rad_s.to_vec()), ("velocity_m_s", velocity_m_s.to_vec())]
            }
            Self::ConstantAcceleration { omega_rad_s, velocity_m_s, alpha_rad_s2, accel_m_s2 } => vec![
                ("omega_rad_s", omega_rad_s.to_vec()),
                ("velocity_m_s", velocity_m_s.to_vec()),
                ("alpha_rad_s2", alpha_rad_s2.to_vec()),
                ("accel_m_s2", accel_m_s2.to_vec()),
            ],
            Self::PiecewiseConstant { omega_rad_s, velocity_m_s } => {
                vec![("omega_rad_s", flat(omega_rad_s)), ("velocity_m_s", flat(velocity_m_s))]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_format_examples_parse_and_round_trip() {
        let cv = "model = \"constant_velocity\"\nomega_rad_s = [0.1, -0.2, 0.05]\nvelocity_m_s = [0.3, 0.0, 0.1]\n";
        let m = MotionRecord::parse(cv).unwrap();
        assert_eq!(m, MotionRecord::ConstantVelocity { omega_rad_s: [0.1, -0.2, 0.05], velocity_m_s: [0.3, 0.0, 0.1] });
        let pw = MotionRecord::PiecewiseConstant {
            omega_rad_s: vec![[0.1, 0.0, 0.0], [0.0, 0.2, 0.0]],
            velocity_m_s: vec![[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]],
        };
        let ca = MotionRecord::ConstantAcceleration {
            omega_rad_s: [0.1, 0.2, 0.3],
            velocity_m_s: [1.0, 0.0, 0.0],
            alpha_rad_s2: [0.0, 1.0, 0.0],
            accel_m_s2: [0.0, 0.0, -2.5],
        };
        for m in [m, pw, ca] {
            assert_eq!(MotionRecord::parse(&m.to_toml_string()).unwrap(), m);
        }
    }

    #[test]
    fn bad_files_name_the_key() {
        let unknown = "model = \"constant_velocity\"\nomega_rad_s = [0,0,0]\nvelocity_m_s = [0,0,0]\nspeed = 3\n";
        assert!(MotionRecord::parse(unknown).unwrap_err().contains("speed"));
        let short = "model = \"constant_velocity\"\nomega_rad_s = [0,0]\nvelocity_m_s = [0,0,0]\n";
        assert!(MotionRecord::parse(short).unwrap_err().contains("omega_rad_s"));
        let segs = "model = \"piecewise_constant\"\nsegments = 3\nomega_rad_s = [[0,0,0]]\nvelocity_m_s = [[0,0,0]]\n";
        assert!(MotionRecord::parse(segs).unwrap_err().contains("segments"));
        let model = "model = \"spline\"\nomega_rad_s = [0,0,0]\nvelocity_m_s = [0,0,0]\n";
        assert!(MotionRecord::parse(model).unwrap_err().contains("unknown model `spline`"));
    }
}
