//! Vector helpers and the SPEC 3.4 pinhole camera shared by the CPU
//! references of the ray-marched kernels (heightfield, clouds); the WGSL
//! twin is `shaders/lib/geometry.wgsl`.

use super::Real;
use crate::ParamError;

/// A 3-vector, y up.
pub type V3 = [Real; 3];

pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn scale(a: V3, s: Real) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
pub(crate) fn dot(a: V3, b: V3) -> Real {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
pub(crate) fn length(a: V3) -> Real {
    dot(a, a).sqrt()
}
pub(crate) fn normalize(a: V3) -> V3 {
    scale(a, 1.0 / length(a))
}
pub(crate) fn mix3(a: V3, b: V3, t: Real) -> V3 {
    add(scale(a, 1.0 - t), scale(b, t))
}
pub(crate) fn smoothstep(e0: Real, e1: Real, x: Real) -> Real {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Unit vector at azimuth `az` (from +z toward +x) and elevation `el`, radians.
pub fn direction(az: Real, el: Real) -> V3 {
    [el.cos() * az.sin(), el.sin(), el.cos() * az.cos()]
}

fn fmt3(v: V3) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}

/// The pinhole camera of SPEC 3.4.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    /// Eye position (km in the kernels that use it).
    pub pos: V3,
    /// Unit view direction f.
    pub forward: V3,
    /// Unit right vector r = normalize(cross(f, (0, 1, 0))).
    pub right: V3,
    /// Unit up vector cross(r, f).
    pub up: V3,
    /// tan(fov / 2), fov vertical.
    pub tan_half: Real,
    /// W / H.
    pub aspect: Real,
}

impl Camera {
    /// f = normalize(target - pos), then the basis of [`Camera::looking`].
    /// Errors when target == pos or the view is vertical (r undefined).
    pub fn new(pos: V3, target: V3, fov_deg: Real, aspect: Real) -> Result<Camera, ParamError> {
        let delta = sub(target, pos);
        let dist = length(delta);
        if dist < 1e-9 {
            return Err(ParamError::Invalid(format!(
                "heightfield: camera_target ({}) equals camera_pos ({}); the view direction is undefined",
                fmt3(target),
                fmt3(pos)
            )));
        }
        let forward = scale(delta, 1.0 / dist);
        // |cross(f, y)| = sin of the angle to the vertical; 1e-6 rad is still
        // well conditioned in f32 once normalised here in Real.
        if length(cross(forward, [0.0, 1.0, 0.0])) < 1e-6 {
            return Err(ParamError::Invalid(format!(
                "heightfield: the view direction camera_target - camera_pos = ({}) is vertical, so \
                 right = cross(f, (0,1,0)) is zero; move camera_target off the vertical through camera_pos",
                fmt3(delta)
            )));
        }
        Ok(Camera::looking(pos, forward, fov_deg, aspect))
    }

    /// r = normalize(cross(f, (0,1,0))), up = cross(r, f) for a unit,
    /// non-vertical `forward`.
    pub fn looking(pos: V3, forward: V3, fov_deg: Real, aspect: Real) -> Camera {
        let right = normalize(cross(forward, [0.0, 1.0, 0.0]));
        let up = cross(right, forward);
        Camera { pos, forward, right, up, tan_half: (fov_deg.to_radians() * 0.5).tan(), aspect }
    }

    /// Unit ray direction through the pixel-centre coordinates (u, v).
    pub fn ray(&self, u: Real, v: Real) -> V3 {
        let a = (2.0 * u - 1.0) * self.tan_half * self.aspect;
        let b = (1.0 - 2.0 * v) * self.tan_half;
        normalize(add(self.forward, add(scale(self.right, a), scale(self.up, b))))
    }
}
