//! `heron view`: a viewer for heron's EXRs in the browser, served from the loopback
//! address. It shows what a general HDR viewer (tev, which pbrt-v4 and Mitsuba users
//! pipe renders to) shows, exposure, display transform, channels, zoom, pixel values
//! and an A/B flip, and what none of them do: a pixel's spectrum over the EXR's bins
//! (Fichet, Pacanowski & Wilkie 2021's layout), its Stokes components S1–S3 per bin
//! and their DoLP/AoLP, its standard error from the variance channels, `heron
//! compare`'s z-score map of two files as an overlay, and the provenance.
//!
//! The page (`page/`: HTML, script and style) is compiled into the binary. Pixels go to
//! it as binary arrays, never as JSON per pixel: a view is drawn here as 8-bit RGBA with
//! heron's own display transform (so the page shows what `heron display` and the PNG
//! previews show), a channel's raw values are little-endian f32; only the one pixel
//! under the pointer is described in JSON.
//!
//! What it serves, and nothing else (any other path is a 404, and a path with `..` or
//! an escaped byte a 403):
//!
//! | path | answer |
//! | --- | --- |
//! | `/`, `/viewer.js`, `/viewer.css` | the page |
//! | `/api/images` | the images: size, channels, views, bins, provenance (JSON) |
//! | `/api/generation` | a counter bumped when a render in progress updates its image |
//! | `/api/image/I/view?view=V&ev=EV&mode=hue\|clip&step=S` | view V of image I as RGBA8, one pixel per S×S block |
//! | `/api/image/I/channel/K` | channel K of image I as f32 LE |
//! | `/api/image/I/pixel?x=X&y=Y` | every channel's value at (X, Y), the spectrum (JSON) |
//! | `/api/compare/A/B` | `heron compare`'s heat map of A against B as RGBA8 |
//!
//! The server listens on 127.0.0.1 only and answers only requests whose Host header
//! names that address (or `localhost`) and its port, so that a web page elsewhere
//! cannot reach it through a DNS name rebound to 127.0.0.1.
use crate::compare::{compare, Image, Options};
use crate::spectrum::display::{DisplayMode, DisplayTransform};
use crate::{HeronError, Result};
use serde_json::{json, Value};
use std::net::{Ipv4Addr, TcpListener};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, RwLock};

pub mod http;
pub mod image;
pub mod show;

pub use http::{Request, Response};
pub use image::ViewImage;
pub use show::View;

const INDEX_HTML: &str = include_str!("page/index.html");
const VIEWER_JS: &str = include_str!("page/viewer.js");
const VIEWER_CSS: &str = include_str!("page/viewer.css");

/// The images being served and the counter the page polls to see a render's progress.
pub struct Viewer {
    images: RwLock<Vec<Arc<ViewImage>>>,
    generation: AtomicU64,
    port: u16,
    /// True while the files given are still being read: requests for images wait, so
    /// that the browser can start and load the page while a large EXR decodes.
    loading: (Mutex<bool>, Condvar),
}

impl Viewer {
    /// A viewer of `images` that will be reached at 127.0.0.1:`port`.
    pub fn new(images: Vec<ViewImage>, port: u16) -> Viewer {
        Viewer {
            images: RwLock::new(images.into_iter().map(Arc::new).collect()),
            generation: AtomicU64::new(0),
            port,
            loading: (Mutex::new(false), Condvar::new()),
        }
    }

    /// Requests for images wait from now until [`Viewer::loaded`].
    pub fn loading(&self) {
        *self.loading.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
    }

    /// The files are read: waiting requests go on.
    pub fn loaded(&self) {
        *self.loading.0.lock().unwrap_or_else(|e| e.into_inner()) = false;
        self.loading.1.notify_all();
    }

    fn wait_loaded(&self) {
        let mut busy = self.loading.0.lock().unwrap_or_else(|e| e.into_inner());
        while *busy {
            busy = self.loading.1.wait(busy).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// Puts `image` in place of image `index` (a render in progress, or its finished
    /// file), or after the last one, and tells the page.
    pub fn replace(&self, index: usize, image: ViewImage) {
        let mut images = self.images.write().unwrap_or_else(|e| e.into_inner());
        if index < images.len() {
            images[index] = Arc::new(image);
        } else {
            images.push(Arc::new(image));
        }
        self.generation.fetch_add(1, Ordering::SeqCst);
    }

    fn image(&self, index: &str) -> std::result::Result<Arc<ViewImage>, Response> {
        let images = self.images.read().unwrap_or_else(|e| e.into_inner());
        index
            .parse::<usize>()
            .ok()
            .and_then(|i| images.get(i).cloned())
            .ok_or_else(|| {
                Response::error(
                    404,
                    format!(
                        "no image {index}: the viewer was given {} (numbered from 0)",
                        images.len()
                    ),
                )
            })
    }

    /// Whether a request's Host header names this server.
    fn host_ok(&self, host: Option<&str>) -> bool {
        let p = self.port;
        host.is_some_and(|h| {
            [
                format!("127.0.0.1:{p}"),
                format!("localhost:{p}"),
                format!("[::1]:{p}"),
            ]
            .iter()
            .any(|ok| h.eq_ignore_ascii_case(ok))
        })
    }

    /// The answer to one request.
    pub fn respond(&self, req: &Request) -> Response {
        if !self.host_ok(req.host.as_deref()) {
            return Response::error(
                403,
                format!(
                    "refused: expected the Host 127.0.0.1:{} or localhost:{}, got {:?}",
                    self.port, self.port, req.host
                ),
            );
        }
        if req.method != "GET" {
            return Response::error(405, format!("expected GET, got {}", req.method));
        }
        if req.path.contains("..") || req.path.contains('%') || req.path.contains('\\') {
            return Response::error(
                403,
                format!(
                    "refused {:?}: the viewer serves only its page and the images it was given",
                    req.path
                ),
            );
        }
        let parts: Vec<&str> = req.path.split('/').skip(1).collect();
        if parts.first() == Some(&"api") {
            self.wait_loaded();
        }
        let answer = match parts.as_slice() {
            [""] => Ok(Response::ok("text/html; charset=utf-8", INDEX_HTML.into())),
            ["viewer.js"] => Ok(Response::ok(
                "text/javascript; charset=utf-8",
                VIEWER_JS.into(),
            )),
            ["viewer.css"] => Ok(Response::ok("text/css; charset=utf-8", VIEWER_CSS.into())),
            // Browsers ask for an icon unprompted; there is none, and that is no error.
            ["favicon.ico"] => Ok(Response::ok("image/x-icon", Vec::new()).with_status(204)),
            ["api", "images"] => Ok(Response::json(&self.listing())),
            ["api", "generation"] => Ok(Response::json(
                &json!({ "generation": self.generation.load(Ordering::SeqCst) }),
            )),
            ["api", "image", i, "view"] => self.view(i, req),
            ["api", "image", i, "channel", k] => self.channel(i, k),
            ["api", "image", i, "pixel"] => self.pixel(i, req),
            ["api", "compare", a, b] => self.compare(a, b),
            _ => Err(Response::error(
                404,
                format!(
                    "not found: {:?}; the viewer serves only its page and the images it was given",
                    req.path
                ),
            )),
        };
        answer.unwrap_or_else(|e| e)
    }

    fn listing(&self) -> Value {
        let images = self.images.read().unwrap_or_else(|e| e.into_inner());
        let list: Vec<Value> = images
            .iter()
            .enumerate()
            .map(|(i, img)| {
                json!({
                    "index": i,
                    "name": img.name,
                    "width": img.width,
                    "height": img.height,
                    "channels": img.channels.iter().map(|c| &c.name).collect::<Vec<_>>(),
                    "views": View::list(img).iter()
                        .map(|(id, label)| json!({"id": id, "label": label}))
                        .collect::<Vec<_>>(),
                    "bins": img.bins().iter().map(|b| b.lambda).collect::<Vec<_>>(),
                    "polarised": img.stokes().is_some(),
                    "variance": img.variance().is_some(),
                    "provenance": img.provenance,
                })
            })
            .collect();
        json!({
            "generation": self.generation.load(Ordering::SeqCst),
            "images": list,
        })
    }

    fn view(&self, i: &str, req: &Request) -> std::result::Result<Response, Response> {
        let img = self.image(i)?;
        let id = req.get("view").unwrap_or("rgb");
        let view = View::parse(id, &img).ok_or_else(|| {
            Response::error(
                400,
                format!(
                    "view: expected one of {}, got {id:?}",
                    View::list(&img)
                        .iter()
                        .map(|(v, _)| v.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?;
        let mode = DisplayMode::parse(req.get("mode").unwrap_or("hue"))
            .map_err(|e| Response::error(400, format!("mode: {e}")))?;
        let ev: f64 = req
            .get("ev")
            .unwrap_or("0")
            .parse()
            .map_err(|_| Response::error(400, "ev: expected a number of stops, e.g. -1.5"))?;
        let t = DisplayTransform::new(mode, ev)
            .map_err(|e| Response::error(400, format!("ev: {e}")))?;
        let step: u32 = req
            .get("step")
            .unwrap_or("1")
            .parse()
            .ok()
            .filter(|s| (1..=256).contains(s))
            .ok_or_else(|| {
                Response::error(
                    400,
                    "step: expected image pixels per picture pixel, 1 to 256",
                )
            })?;
        Ok(
            Response::ok("application/octet-stream", view.draw_scaled(&img, &t, step))
                .with_header("X-Width", img.width.div_ceil(step).to_string())
                .with_header("X-Height", img.height.div_ceil(step).to_string()),
        )
    }

    fn channel(&self, i: &str, k: &str) -> std::result::Result<Response, Response> {
        let img = self.image(i)?;
        let c = k
            .parse::<usize>()
            .ok()
            .and_then(|k| img.channels.get(k))
            .ok_or_else(|| {
                Response::error(
                    404,
                    format!(
                        "no channel {k}: image {i} has {} (numbered from 0)",
                        img.channels.len()
                    ),
                )
            })?;
        let bytes = c.data.iter().flat_map(|v| v.to_le_bytes()).collect();
        Ok(Response::ok("application/octet-stream", bytes))
    }

    fn pixel(&self, i: &str, req: &Request) -> std::result::Result<Response, Response> {
        let img = self.image(i)?;
        let coord = |key: &str, len: u32| {
            req.get(key)
                .and_then(|v| v.parse::<u32>().ok())
                .filter(|&v| v < len)
                .ok_or_else(|| {
                    Response::error(
                        400,
                        format!(
                            "{key}: expected a pixel index in 0..{len}, got {:?}",
                            req.get(key)
                        ),
                    )
                })
        };
        let (x, y) = (coord("x", img.width)?, coord("y", img.height)?);
        Ok(Response::json(&pixel_json(&img, x, y)))
    }

    fn compare(&self, a: &str, b: &str) -> std::result::Result<Response, Response> {
        let (ia, ib) = (self.image(a)?, self.image(b)?);
        let as_image = |img: &ViewImage| -> Result<Image> {
            let n = img.pixels();
            let values = (0..n).map(|i| img.rgb(i).unwrap_or([0.0; 3])).collect();
            let variance = img
                .variance()
                .map(|v| (0..n).map(|i| v.map(|p| p[i])).collect());
            Image::new(
                &img.name,
                img.width,
                img.height,
                ["R", "G", "B"],
                values,
                variance,
            )
        };
        let c = as_image(&ia)
            .and_then(|x| Ok((x, as_image(&ib)?)))
            .and_then(|(x, y)| compare(&x, &y, &Options::default()))
            .map_err(|e| Response::error(400, format!("cannot compare: {e}")))?;
        let heat = c.heat_map(None);
        let rgba = heat
            .pixels()
            .flat_map(|p| [p.0[0], p.0[1], p.0[2], 255])
            .collect();
        Ok(Response::ok("application/octet-stream", rgba)
            .with_header("X-Heron-Same", c.same().to_string())
            .with_header("X-Heron-Max-Abs-Z", format!("{:.3}", c.max_abs_z()))
            .with_header("X-Heron-Tests", c.tests().to_string()))
    }
}

/// What the page shows of one pixel.
fn pixel_json(img: &ViewImage, x: u32, y: u32) -> Value {
    let i = (y * img.width + x) as usize;
    let bins = img.bins();
    let at = |c: Option<usize>| c.map(|c| img.channels[c].data[i]);
    let component = |k: usize| -> Option<Vec<Option<f32>>> {
        bins.iter()
            .any(|b| b.stokes[k].is_some())
            .then(|| bins.iter().map(|b| at(b.stokes[k])).collect())
    };
    let stokes = img.stokes().map(|s| {
        let rgb = s.map(|c| c.map(|p| p[i]));
        let film = img.stokes_film().expect("polarised");
        let xyz = film.xyz[i];
        let st = film.stokes.as_ref().expect("polarised")[i];
        let (s0, s1, s2) = (xyz[1] as f64, st[0][1] as f64, st[1][1] as f64);
        let dolp = (s0 > 0.0).then(|| (s1.hypot(s2) / s0).min(1.0));
        json!({
            "s1": rgb[0], "s2": rgb[1], "s3": rgb[2],
            "dolp": dolp,
            "aolp_deg": dolp.map(|_| 0.5 * s2.atan2(s1).to_degrees()),
        })
    });
    json!({
        "image": img.name,
        "x": x,
        "y": y,
        "rgb": img.rgb(i),
        "xyz": img.xyz(i),
        "stderr": img.variance().map(|v| v.map(|p| p[i].max(0.0).sqrt())),
        "channels": img.channels.iter().map(|c| json!([c.name, c.data[i]])).collect::<Vec<_>>(),
        "spectrum": {
            "lambda": bins.iter().map(|b| b.lambda).collect::<Vec<_>>(),
            "s0": component(0),
            "s1": component(1),
            "s2": component(2),
            "s3": component(3),
        },
        "stokes": stokes,
    })
}

/// A listener on 127.0.0.1:`port` (0: a free port the system picks). Errors say which
/// port could not be had.
pub fn bind(port: u16) -> Result<TcpListener> {
    TcpListener::bind((Ipv4Addr::LOCALHOST, port)).map_err(|e| {
        HeronError::Invalid(format!(
            "--port: cannot listen on 127.0.0.1:{port}: {e} (0 picks a free port)"
        ))
    })
}

/// Answers requests on `listener` until the process ends, each connection on a thread
/// of its own.
pub fn serve(listener: TcpListener, viewer: Arc<Viewer>) {
    for stream in listener.incoming().flatten() {
        let viewer = viewer.clone();
        std::thread::spawn(move || http::handle(stream, |req| viewer.respond(req)));
    }
}

#[cfg(test)]
mod tests {
    use super::image::Channel;
    use super::*;

    fn viewer() -> Viewer {
        let ch = |name: &str, v: f32| Channel {
            name: name.into(),
            data: vec![v; 6],
        };
        let img = ViewImage {
            name: "a.exr".into(),
            width: 3,
            height: 2,
            channels: vec![
                ch("R", 0.5),
                ch("G", 0.25),
                ch("B", 1.0),
                ch("S0.500,000000nm", 2.0),
            ],
            provenance: vec![("spp".into(), "4".into())],
        };
        Viewer::new(vec![img], 4242)
    }

    fn get(v: &Viewer, target: &str) -> Response {
        let req =
            Request::parse(&format!("GET {target} HTTP/1.1\r\nHost: 127.0.0.1:4242")).unwrap();
        v.respond(&req)
    }

    #[test]
    fn only_the_page_and_the_images_are_served() {
        let v = viewer();
        assert_eq!(get(&v, "/").status, 200);
        assert_eq!(get(&v, "/viewer.js").status, 200);
        for bad in [
            "/../Cargo.toml",
            "/api/image/0/../../etc/passwd",
            "/%2e%2e/Cargo.toml",
            "/viewer.js%00",
            "/..\\Cargo.toml",
        ] {
            assert_eq!(get(&v, bad).status, 403, "{bad}");
        }
        for missing in [
            "/Cargo.toml",
            "/etc/passwd",
            "/api/image/1/channel/0",
            "/api/image/0/channel/4",
            "/api/image/x/view",
        ] {
            assert_eq!(get(&v, missing).status, 404, "{missing}");
        }
        let other_host = Request::parse("GET / HTTP/1.1\r\nHost: evil.example:4242").unwrap();
        assert_eq!(v.respond(&other_host).status, 403);
        let post = Request::parse("POST / HTTP/1.1\r\nHost: localhost:4242").unwrap();
        assert_eq!(v.respond(&post).status, 405);
    }

    #[test]
    fn channels_go_as_f32_and_views_as_rgba() {
        let v = viewer();
        let r = get(&v, "/api/image/0/channel/3");
        assert_eq!(r.body.len(), 6 * 4);
        assert_eq!(f32::from_le_bytes(r.body[..4].try_into().unwrap()), 2.0);
        let r = get(&v, "/api/image/0/view?view=rgb&ev=0&mode=clip");
        assert_eq!(r.body.len(), 6 * 4);
        let t = DisplayTransform::new(DisplayMode::Clip, 0.0).unwrap();
        assert_eq!(&r.body[..3], &t.encode_u8([0.5, 0.25, 1.0]));
        let brighter = get(&v, "/api/image/0/view?view=rgb&ev=1&mode=clip");
        assert_ne!(brighter.body, r.body);
        assert_eq!(get(&v, "/api/image/0/view?ev=abc").status, 400);
        assert_eq!(get(&v, "/api/image/0/view?step=0").status, 400);
        let half = get(&v, "/api/image/0/view?view=rgb&ev=0&mode=clip&step=2");
        // 3×2 pixels in 2×2 blocks: 2×1 picture pixels of 4 bytes.
        assert_eq!(half.body.len(), 8);
        assert_eq!(&half.body[..3], &t.encode_u8([0.5, 0.25, 1.0]));
        assert_eq!(get(&v, "/api/image/0/view?view=dolp").status, 400);
        assert_eq!(get(&v, "/api/image/0/pixel?x=3&y=0").status, 400);
        let p: Value = serde_json::from_slice(&get(&v, "/api/image/0/pixel?x=2&y=1").body).unwrap();
        assert_eq!(p["rgb"], json!([0.5, 0.25, 1.0]));
        assert_eq!(p["spectrum"]["lambda"], json!([500.0]));
        assert_eq!(p["spectrum"]["s0"], json!([2.0]));
    }
}
