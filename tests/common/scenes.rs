//! The scenes in `scenes/`, for the tests that hold every one of them to a rule.
use heron::camera::Camera;
use heron::scene::{load_scene, Scene};
use std::path::Path;

/// The file names of the scenes in `scenes/`, sorted (at least ten of them).
pub fn names() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 10, "{names:?}");
    names
}

/// The scene `name` of `scenes/`, its camera's image resized to `width` × `height`.
pub fn load_small(name: &str, width: u32, height: u32) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let mut s = load_scene(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
    let c = &s.camera;
    s.camera = Camera::new(c.eye, c.look_at, c.up, c.d, width, height).unwrap();
    s
}

/// A white furnace around a medium: an environment of radiance 1, the sphere of radius 1
/// at the origin holding `medium` (a TOML inline table) behind an index-matched boundary,
/// seen whole by a 32×32 camera, paths up to 1000 events long; `extra` is appended (TOML:
/// a material for the sphere, lights).
pub fn furnace_sphere(medium: &str, extra: &str) -> String {
    format!(
        r#"
background = 1.0
[camera]
eye = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
d = 2.5
resolution = [32, 32]
[render]
max_depth = 1000
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
medium = {medium}
{extra}
"#
    )
}

/// A dense-flint ball (N-SF11) on a white floor under a small spherical area light, seen
/// by a `width` × `height` camera, paths of up to 8 events: its caustic is refraction
/// paths only, which end the companion wavelengths at every refraction
/// (`tests/transport.rs`, `tests/sppm.rs`).
pub fn flint_caustic(width: u32, height: u32) -> String {
    format!(
        r#"
[camera]
eye = [0.0, 1.2, 2.2]
look_at = [0.0, 0.2, 0.0]
resolution = [{width}, {height}]
[render]
max_depth = 8
[materials.floor]
type = "lambertian"
rho_d = 0.8
[materials.flint]
type = "dielectric"
ior = "N-SF11"
[[shapes]]
type = "quad"
origin = [-2.0, 0.0, 2.0]
edge1 = [4.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -4.0]
material = "floor"
[[shapes]]
type = "sphere"
center = [0.0, 0.4, 0.0]
radius = 0.4
material = "flint"
[[shapes]]
type = "sphere"
center = [0.6, 1.6, 0.2]
radius = 0.3
emission = {{ spectrum = "E", scale = 20.0 }}
"#
    )
}

/// A Mitsuba 3 scene around `body` with a 40 × 20 box-filtered sensor looking at the
/// origin from +z, so that the body's elements are what an import test tests.
pub fn mitsuba_around(body: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="20"/><rfilter type="box"/></film>
    </sensor>
{body}
</scene>
"#
    )
}
