//! `grains movie` and `grains view` on a short run of the built-in default:
//! the files they write, the frames the server sends, and the errors a user
//! can meet (bad options, a taken port, missing or truncated frames).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn grains(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_grains"))
        .args(args)
        .output()
        .expect("start grains");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code(), text)
}

/// A fresh run of 60 steps of the default with 7 frames, in its own directory.
fn short_run(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("grains-view-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    let (code, text) = grains(&[
        "run",
        "--steps",
        "60",
        "--set",
        "output.movie=false",
        "--set",
        "output.every=0.0001",
        "--quiet",
        "--out",
        d,
    ]);
    assert_eq!(code, Some(0), "{text}");
    dir
}

fn frames(dir: &Path) -> usize {
    std::fs::read_dir(dir.join("frames")).unwrap().count()
}

#[test]
fn movie_draws_every_frame_and_names_bad_input() {
    let dir = short_run("movie");
    let d = dir.to_str().unwrap();
    let n = frames(&dir);
    assert!(n >= 3, "{n} frames");
    assert!(dir.join("scene.json").is_file());
    let (code, text) = grains(&["movie", d, "--fps", "5", "--no-mp4", "--color", "height"]);
    assert_eq!(code, Some(0), "{text}");
    let mut dec = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(dir.join("movie.gif")).unwrap())
        .unwrap();
    let mut count = 0;
    while let Some(f) = dec.read_next_frame().unwrap() {
        assert_eq!(f.delay, 20);
        count += 1;
    }
    assert_eq!(count, n);

    let (code, text) = grains(&["movie", d, "--color", "colour"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("--color colour") && text.contains("speed, height, id, kind"));
    let (code, text) = grains(&["movie", d, "--view", "w"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("allowed: x, y, z"), "{text}");

    // A frame cut short, as by a killed run: named, exit 2.
    let last = dir.join(format!("frames/frame_{:06}.vtp", n - 1));
    let text_of = std::fs::read_to_string(&last).unwrap();
    std::fs::write(&last, &text_of[..text_of.len() / 3]).unwrap();
    let (code, text) = grains(&["movie", d, "--no-mp4"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains(&format!("frame_{:06}.vtp", n - 1)) && text.contains("truncated"));
    // No frames at all.
    std::fs::remove_file(dir.join("frames.pvd")).unwrap();
    let (code, text) = grains(&["view", d, "--port", "0"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(
        text.contains("frames.pvd") && text.contains("not found"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// At `--width 480` the band under each frame keeps all it draws inside
/// the picture: its last columns stay blank (the height legend's last
/// number and unit were cut there).
#[test]
fn movie_legend_fits_a_narrow_picture() {
    let dir = short_run("narrow");
    let d = dir.to_str().unwrap();
    let (code, text) = grains(&[
        "movie", d, "--view", "z", "--width", "480", "--color", "height", "--no-mp4",
    ]);
    assert_eq!(code, Some(0), "{text}");
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts
        .read_info(std::fs::File::open(dir.join("movie.gif")).unwrap())
        .unwrap();
    let (w, h) = (dec.width() as usize, dec.height() as usize);
    assert_eq!(w, 480);
    let f = dec.read_next_frame().unwrap().expect("a frame");
    assert_eq!((f.width as usize, f.height as usize), (w, h));
    // The band: the bottom 14 rows (text scale 1 below 700 pixels).
    let mut ink = 0;
    for y in h - 14..h {
        for x in 0..w {
            let p = &f.buffer[(y * w + x) * 4..][..3];
            if p.iter().any(|&c| c < 200) {
                ink += 1;
                assert!(x < w - 3, "the band is drawn to the edge at ({x}, {y})");
            }
        }
    }
    assert!(ink > 100, "no band drawn");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The default run's displacement.png has a band under the grains with
/// the time span, a scale bar and its legend in black text (the arrows
/// were once all there was), and its tracers are a few colours, not one.
#[test]
fn displacement_picture_has_its_band() {
    let dir = short_run("displacement");
    let dec = png::Decoder::new(std::fs::File::open(dir.join("displacement.png")).unwrap());
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let (w, h) = (info.width as usize, info.height as usize);
    let px = |x: usize, y: usize| -> [u8; 3] {
        let k = (y * w + x) * 3;
        [buf[k], buf[k + 1], buf[k + 2]]
    };
    // Text scale 2 at 1000 pixels: a band of 28 rows.
    let band = 28;
    let black = (h - band..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| px(x, y) == [0, 0, 0])
        .count();
    assert!(black > 300, "{black} black pixels in the band");
    // Nothing but white and black in the band's top rows above the text.
    for y in h - band..h - band + 4 {
        for x in 0..w {
            assert_eq!(px(x, y), [255; 3], "({x}, {y}) in the band's margin");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// One GET over a fresh connection: (status line, body).
fn get(addr: &str, path: &str) -> (String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    write!(s, "GET {path} HTTP/1.0\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut all = Vec::new();
    s.read_to_end(&mut all).unwrap();
    let split = all.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&all[..split]).into_owned();
    (
        head.lines().next().unwrap_or("").to_string(),
        all[split + 4..].to_vec(),
    )
}

#[test]
fn view_serves_packed_frames_on_loopback_and_refuses_a_taken_port() {
    let dir = short_run("view");
    let d = dir.to_str().unwrap();
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let (code, text) = grains(&["view", d, "--port", &port]);
    assert_eq!(code, Some(2), "{text}");
    assert!(
        text.contains(&format!("port {port} on 127.0.0.1 is taken")),
        "{text}"
    );

    let mut child = Command::new(env!("CARGO_BIN_EXE_grains"))
        .args(["view", d, "--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let start = line.find("http://127.0.0.1:").expect(&line) + "http://".len();
    let addr = line[start..].split('/').next().unwrap().to_string();

    let (status, body) = get(&addr, "/api/meta");
    assert!(status.contains("200"), "{status}");
    let meta: serde_json::Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(meta["dimension"], 2);
    assert_eq!(meta["times"].as_array().unwrap().len(), frames(&dir));
    let (status, body) = get(&addr, "/api/frame/1");
    assert!(status.contains("200"), "{status}");
    assert_eq!(&body[..4], b"GRF1");
    assert_eq!(body.len(), 24 + 28 * 200);
    let (_, walls) = get(&addr, "/api/walls/1");
    let walls: serde_json::Value = serde_json::from_slice(&walls).unwrap();
    assert_eq!(walls[0]["type"], "line", "{walls}");
    let (status, body) = get(&addr, "/api/frame/9999");
    assert!(status.contains("404"), "{status}");
    assert!(String::from_utf8_lossy(&body).contains("no frame 9999"));
    let (status, page) = get(&addr, "/");
    assert!(status.contains("200") && String::from_utf8_lossy(&page).contains("viewer.js"));
    child.kill().unwrap();
    let _ = child.wait();
    let _ = std::fs::remove_dir_all(&dir);
}
