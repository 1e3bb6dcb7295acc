//! The default light rig: what a scene without lights is lit by, so that a glTF model that ships
//! none (most of the Khronos samples) is never a black image.
//!
//! Two directional lights placed from the camera, as a photographer's key and fill: the key from
//! the viewer's upper left and a little behind them, so every surface that faces the camera and
//! turns up or left is lit; a dim fill from the right at eye height, so that the key's shadowed
//! side is not black. Directional lights need no range and cover any scene size, and every
//! technique draws them (as full-screen passes), so the rig changes nothing about what is
//! measured.

use crate::{Camera, Light, LightKind, Scene};
use glam::Vec3;

/// The key light's radiance scale: a white Lambert surface facing it comes out at about 0.7
/// after the tonemap (exposure 1, Reinhard, sRGB).
pub const KEY_RADIANCE: f32 = 3.0;

/// The fill's share of the key.
pub const FILL_SHARE: f32 = 0.25;

/// The two lights of the rig for `camera`: key first, then fill.
pub fn default_light_rig(camera: &Camera) -> [Light; 2] {
    let forward = (camera.target - camera.eye).normalize_or(Vec3::NEG_Z);
    let right = forward.cross(camera.up).normalize_or(Vec3::X);
    let up = right.cross(forward);
    // Where each light comes from; the light travels the other way.
    let key_from = (up - 0.7 * right - 0.5 * forward).normalize();
    let fill_from = (0.8 * right - 0.6 * forward - 0.1 * up).normalize();
    let directional = |from: Vec3, radiance: f32| Light {
        kind: LightKind::Directional { direction: -from },
        position: Vec3::ZERO,
        radius: 0.0,
        color: Vec3::splat(radiance),
        falloff: crate::Falloff::SquaredWindow,
    };
    [
        directional(key_from, KEY_RADIANCE),
        directional(fill_from, KEY_RADIANCE * FILL_SHARE),
    ]
}

/// Whether a scene without lights gets the default rig.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DefaultLights {
    /// A scene without lights is lit by [`default_light_rig`].
    IfNone,
    /// Scenes keep the lights they have, none included (the frame is then black).
    Off,
}

/// `scene`, with the default rig added when it has no lights and `policy` asks for it; the bool
/// says whether it was added.
pub fn with_default_lights(mut scene: Scene, policy: DefaultLights) -> (Scene, bool) {
    let add = policy == DefaultLights::IfNone && scene.lights.is_empty();
    if add {
        scene.lights = default_light_rig(&scene.camera).to_vec();
    }
    (scene, add)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shade;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_radians: 0.9,
            near: 0.1,
            far: 100.0,
        }
    }

    /// The key comes from above, from the viewer's left and from the viewer's side; the fill
    /// from the right; both are unit directions and the fill is dimmer.
    #[test]
    fn the_key_lights_from_the_upper_left_and_the_fill_from_the_right() {
        let [key, fill] = default_light_rig(&camera());
        let (LightKind::Directional { direction: k }, LightKind::Directional { direction: f }) =
            (key.kind, fill.kind)
        else {
            panic!("the rig is directional");
        };
        assert!((k.length() - 1.0).abs() < 1e-6 && (f.length() - 1.0).abs() < 1e-6);
        // Travelling down, to the right (+X) and away from the viewer (-Z).
        assert!(k.y < 0.0 && k.x > 0.0 && k.z < 0.0, "{k}");
        assert!(f.x < 0.0, "{f}");
        assert!(fill.color.x < key.color.x);
    }

    /// A surface facing the camera is lit, whichever way it turns within 60 degrees of the view,
    /// so a light-less model is never black.
    #[test]
    fn every_surface_facing_the_camera_is_lit() {
        let cam = camera();
        let lights = default_light_rig(&cam);
        let to_eye = (cam.eye - cam.target).normalize();
        for i in 0..64 {
            let (a, b) = (i as f32 * 0.39, (i % 8) as f32 * 0.13);
            let tilt = Vec3::new(a.cos() * b.sin(), a.sin() * b.sin(), 0.0) * 2.0;
            let normal = (to_eye + tilt).normalize();
            if normal.dot(to_eye) < 0.5 {
                continue;
            }
            let white = crate::Material::lambert(Vec3::ONE);
            let lit = shade(&lights, &white, cam.target, normal, cam.eye).x;
            assert!(lit > 0.05, "normal {normal}: {lit}");
        }
    }

    #[test]
    fn only_a_scene_without_lights_gets_the_rig() {
        let lit = crate::embedded("default").unwrap();
        let count = lit.lights.len();
        let (kept, added) = with_default_lights(lit, DefaultLights::IfNone);
        assert!(!added);
        assert_eq!(kept.lights.len(), count);
        let mut dark = kept;
        dark.lights.clear();
        let (off, added) = with_default_lights(dark.clone(), DefaultLights::Off);
        assert!(!added && off.lights.is_empty());
        let (rigged, added) = with_default_lights(dark, DefaultLights::IfNone);
        assert!(added);
        assert_eq!(rigged.lights.len(), 2);
        rigged.validate().unwrap();
    }
}
