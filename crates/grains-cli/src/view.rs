//! `grains view RUN_DIR [--port P]`: serves a page on 127.0.0.1 that plays
//! the run in the browser (WebGL2), with frames read from the run directory
//! when the page asks for them and sent in a compact binary form.
//!
//! Routes: `/` the page, `/viewer.js` its script, `/api/meta` the run
//! (dimension, box, frame times), `/api/frame/N` frame N packed
//! ([`pack_frame`]), `/api/walls/N` the walls at frame N's time (JSON
//! wires), `/api/thermo` thermo.csv. The HTTP server is `tiny_http`.

use clap::Args;
use grains::io::{read_series, Frame, FrameEntry};
use grains::render::movie::{load_frame, scene_or_bare};
use grains::render::Scene;
use grains::Error;
use serde_json::json;
use std::io::IsTerminal as _;
use std::net::{Ipv4Addr, TcpListener};
use std::path::{Path, PathBuf};

const PAGE: &str = include_str!("view/index.html");
const SCRIPT: &str = include_str!("view/viewer.js");

#[derive(Args)]
pub struct ViewArgs {
    /// The run's output directory (holding frames.pvd and frames/).
    run_dir: PathBuf,
    /// Port on 127.0.0.1 (0: any free port).
    #[arg(long, default_value_t = 8765)]
    port: u16,
}

/// Magic and version at the start of a packed frame.
pub const MAGIC: &[u8; 4] = b"GRF1";

/// A frame for the page: a 24-byte header (magic, u32 grains, u32
/// dimension, u32 zero, f64 time), then little-endian arrays: f32 x y z per
/// grain, f32 radius, f32 speed, u32 id, u32 kind (28 bytes a grain).
pub fn pack_frame(f: &Frame) -> Vec<u8> {
    let n = f.len();
    let mut out = Vec::with_capacity(24 + 28 * n);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(n as u32).to_le_bytes());
    out.extend_from_slice(&(f.dim as u32).to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&f.time.to_le_bytes());
    for p in &f.pos {
        for c in p {
            out.extend_from_slice(&(*c as f32).to_le_bytes());
        }
    }
    for r in &f.radius {
        out.extend_from_slice(&(*r as f32).to_le_bytes());
    }
    for i in 0..n {
        out.extend_from_slice(&(f.speed(i) as f32).to_le_bytes());
    }
    for id in &f.id {
        out.extend_from_slice(&(*id as u32).to_le_bytes());
    }
    for k in &f.kind {
        out.extend_from_slice(&k.to_le_bytes());
    }
    out
}

/// The run being served.
struct Run {
    dir: PathBuf,
    entries: Vec<FrameEntry>,
    scene: Scene,
}

pub fn run(args: ViewArgs) -> grains::Result<()> {
    let dir = args.run_dir;
    let entries = read_series(&dir)?;
    let first_entry = entries
        .first()
        .ok_or_else(|| Error::input(format!("{}: frames.pvd lists no frames", dir.display())))?;
    // Read the first frame now: a broken run fails here, not in the page.
    let mut first = grains::io::read_frame(&first_entry.path)?;
    let scene = scene_or_bare(&dir, &mut first)?;
    let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, args.port)).map_err(|e| {
        if e.kind() == std::io::ErrorKind::AddrInUse {
            Error::input(format!(
                "port {} on 127.0.0.1 is taken; choose another with --port (0: any free port)",
                args.port
            ))
        } else {
            Error::input(format!("cannot listen on 127.0.0.1:{}: {e}", args.port))
        }
    })?;
    let addr = listener
        .local_addr()
        .map_err(|e| Error::input(format!("127.0.0.1:{}: {e}", args.port)))?;
    let server = tiny_http::Server::from_listener(listener, None)
        .map_err(|e| Error::input(format!("cannot serve on {addr}: {e}")))?;
    let url = format!("http://{addr}/");
    println!(
        "grains view: {} ({} frames) at {url}  (Ctrl-C to stop)",
        dir.display(),
        entries.len()
    );
    use std::io::Write as _;
    let _ = std::io::stdout().flush();
    // Only someone at a terminal wants a browser window; scripts and CI
    // read the address above.
    if std::io::stdout().is_terminal() && std::env::var_os("DISPLAY").is_some() {
        let _ = std::process::Command::new("xdg-open")
            .arg(&url)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn();
    }
    let run = Run {
        dir,
        entries,
        scene,
    };
    for request in server.incoming_requests() {
        let response = answer(&run, request.url());
        // A page closed mid-answer is not an error of the server.
        let _ = request.respond(response);
    }
    Ok(())
}

type Reply = tiny_http::Response<std::io::Cursor<Vec<u8>>>;

fn typed(body: Vec<u8>, mime: &str) -> Reply {
    let header = tiny_http::Header::from_bytes(&b"Content-Type"[..], mime.as_bytes())
        .expect("a valid header");
    tiny_http::Response::from_data(body)
        .with_header(header)
        .with_header(
            tiny_http::Header::from_bytes(&b"Cache-Control"[..], &b"no-store"[..])
                .expect("a valid header"),
        )
}

fn failure(code: u16, msg: String) -> Reply {
    typed(msg.into_bytes(), "text/plain; charset=utf-8").with_status_code(code)
}

fn answer(run: &Run, url: &str) -> Reply {
    let path = url.split('?').next().unwrap_or("");
    let index = |rest: &str| -> Result<usize, Reply> {
        rest.parse::<usize>()
            .ok()
            .filter(|&i| i < run.entries.len())
            .ok_or_else(|| {
                failure(
                    404,
                    format!("no frame {rest}: frames 0 to {}", run.entries.len() - 1),
                )
            })
    };
    match path {
        "/" | "/index.html" => typed(PAGE.as_bytes().to_vec(), "text/html; charset=utf-8"),
        "/viewer.js" => typed(SCRIPT.as_bytes().to_vec(), "text/javascript; charset=utf-8"),
        "/favicon.ico" => typed(Vec::new(), "image/x-icon"),
        "/api/meta" => typed(meta(run).into_bytes(), "application/json"),
        "/api/thermo" => match std::fs::read(run.dir.join("thermo.csv")) {
            Ok(b) => typed(b, "text/csv"),
            Err(e) => failure(404, format!("thermo.csv: {e}")),
        },
        _ => {
            if let Some(rest) = path.strip_prefix("/api/frame/") {
                match index(rest) {
                    Ok(i) => match load_frame(&run.entries[i], &run.scene) {
                        Ok(f) => typed(pack_frame(&f), "application/octet-stream"),
                        Err(e) => failure(500, e.to_string()),
                    },
                    Err(r) => r,
                }
            } else if let Some(rest) = path.strip_prefix("/api/walls/") {
                match index(rest) {
                    Ok(i) => {
                        let wires = run.scene.wires(run.entries[i].time);
                        typed(
                            serde_json::to_vec(&wires).unwrap_or_default(),
                            "application/json",
                        )
                    }
                    Err(r) => r,
                }
            } else {
                failure(404, format!("{path}: not found"))
            }
        }
    }
}

fn meta(run: &Run) -> String {
    let s = &run.scene;
    let finite = |v: [f64; 3]| v.map(|x| if x.is_finite() { json!(x) } else { json!(null) });
    json!({
        "run": name(&run.dir),
        "dimension": s.dim,
        "box_lo": finite(s.box_lo),
        "box_hi": finite(s.box_hi),
        "periodic": s.periodic,
        "times": run.entries.iter().map(|e| e.time).collect::<Vec<_>>(),
    })
    .to_string()
}

fn name(dir: &Path) -> String {
    dir.canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| dir.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_frames_hold_every_grain_in_28_bytes() {
        let f = Frame {
            dim: 2,
            time: 0.5,
            id: vec![3, 9],
            kind: vec![1, 2],
            pos: vec![[1.0, 2.0, 0.0], [3.0, 4.0, 0.0]],
            vel: vec![[3.0, 4.0, 0.0], [0.0; 3]],
            omega: vec![[0.0; 3]; 2],
            radius: vec![0.5, 0.25],
            ..Default::default()
        };
        let b = pack_frame(&f);
        assert_eq!(b.len(), 24 + 2 * 28);
        assert_eq!(&b[..4], MAGIC);
        assert_eq!(u32::from_le_bytes(b[4..8].try_into().unwrap()), 2);
        assert_eq!(f64::from_le_bytes(b[16..24].try_into().unwrap()), 0.5);
        let f32_at = |k: usize| f32::from_le_bytes(b[k..k + 4].try_into().unwrap());
        // Second grain's y, first radius, first speed (|(3, 4)| = 5), ids, kinds.
        assert_eq!(f32_at(24 + 4 * 4), 4.0);
        assert_eq!(f32_at(24 + 24), 0.5);
        assert_eq!(f32_at(24 + 32), 5.0);
        assert_eq!(u32::from_le_bytes(b[64..68].try_into().unwrap()), 3);
        assert_eq!(u32::from_le_bytes(b[76..80].try_into().unwrap()), 2);
    }
}
