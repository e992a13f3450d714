//! Looking at the editor: a private X server (Xvfb, with Mesa's software OpenGL), window
//! capture through the X protocol, PNG output, and a measure of how much a plot shows.
//!
//! Used by `tests/editor.rs` and by `ressort-screenshot` (see `scripts/screenshot.sh`).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use x11rb::connection::Connection;
use x11rb::protocol::xproto::{AtomEnum, ConnectionExt, ImageFormat, ImageOrder, Window};

/// An Xvfb server on a free display, stopped when dropped.
#[derive(Debug)]
pub struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    /// Starts Xvfb with a 24-bit screen of `width` × `height` on the first display number
    /// that is free. None when Xvfb is not installed or does not come up.
    pub fn start(width: u32, height: u32) -> Option<Xvfb> {
        // Tests start servers in parallel: one at a time, and a server that exits at once
        // (its display was taken meanwhile) moves on to the next number.
        static STARTING: std::sync::Mutex<()> = std::sync::Mutex::new(());
        let _one_at_a_time = STARTING.lock().unwrap_or_else(|e| e.into_inner());
        for n in 90..200u32 {
            if Path::new(&format!("/tmp/.X{n}-lock")).exists()
                || Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
            {
                continue;
            }
            let display = format!(":{n}");
            let child = Command::new("Xvfb")
                .arg(&display)
                .args(["-screen", "0", &format!("{width}x{height}x24")])
                .args(["-nolisten", "tcp"])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .ok()?;
            let mut x = Xvfb { child, display };
            let deadline = Instant::now() + Duration::from_secs(10);
            while Instant::now() < deadline {
                if let Ok(Some(_)) = x.child.try_wait() {
                    break;
                }
                // Xlib clients connect through the socket file, which may appear after the
                // abstract socket x11rb can already use.
                let socket = Path::new("/tmp/.X11-unix").join(format!("X{n}"));
                if socket.exists() && x11rb::connect(Some(&x.display)).is_ok() {
                    std::thread::sleep(Duration::from_millis(200));
                    if let Ok(None) = x.child.try_wait() {
                        return Some(x);
                    }
                    break;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        None
    }

    /// The `DISPLAY` value: `:93`.
    pub fn display(&self) -> &str {
        &self.display
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// An RGB image, rows top to bottom.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl Image {
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = ((y * self.width + x) * 3) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Writes the image as a PNG file, creating the folder.
    pub fn save_png(&self, path: &Path) -> Result<(), String> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer
            .write_image_data(&self.rgb)
            .map_err(|e| e.to_string())
    }
}

/// Every window of the display with its name (empty when it has none), depth first from the
/// root.
fn windows(display: &str) -> Vec<(Window, String)> {
    let Ok((conn, screen)) = x11rb::connect(Some(display)) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    let mut stack = vec![conn.setup().roots[screen].root];
    while let Some(w) = stack.pop() {
        let name = conn
            .get_property(false, w, AtomEnum::WM_NAME, AtomEnum::ANY, 0, 256)
            .ok()
            .and_then(|c| c.reply().ok())
            .map(|r| String::from_utf8_lossy(&r.value).into_owned())
            .unwrap_or_default();
        found.push((w, name));
        if let Some(tree) = conn.query_tree(w).ok().and_then(|c| c.reply().ok()) {
            stack.extend(tree.children.iter().rev());
        }
    }
    found
}

/// The first window (depth first from the root) whose name is `name`.
pub fn find_window(display: &str, name: &str) -> Option<Window> {
    windows(display)
        .into_iter()
        .find(|(_, n)| n == name)
        .map(|(w, _)| w)
}

/// Every window name on the display, for error messages.
pub fn window_names(display: &str) -> Vec<String> {
    windows(display)
        .into_iter()
        .map(|(_, n)| n)
        .filter(|n| !n.is_empty())
        .collect()
}

/// Captures a window's contents (a 24-bit TrueColor window, as Xvfb and baseview make).
pub fn capture(display: &str, window: Window) -> Result<Image, String> {
    let (conn, _) = x11rb::connect(Some(display)).map_err(|e| e.to_string())?;
    let geometry = conn
        .get_geometry(window)
        .map_err(|e| e.to_string())?
        .reply()
        .map_err(|e| e.to_string())?;
    let (w, h) = (geometry.width as u32, geometry.height as u32);
    let reply = conn
        .get_image(ImageFormat::Z_PIXMAP, window, 0, 0, w as u16, h as u16, !0)
        .map_err(|e| e.to_string())?
        .reply()
        .map_err(|e| format!("GetImage: {e}"))?;
    let bpp = conn
        .setup()
        .pixmap_formats
        .iter()
        .find(|f| f.depth == reply.depth)
        .map(|f| f.bits_per_pixel as usize)
        .unwrap_or(32);
    if reply.depth < 24 || bpp != 32 {
        return Err(format!(
            "unsupported window format: depth {}, {bpp} bits per pixel",
            reply.depth
        ));
    }
    let lsb = conn.setup().image_byte_order == ImageOrder::LSB_FIRST;
    let stride = reply.data.len() / h.max(1) as usize;
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h as usize {
        for x in 0..w as usize {
            let p = &reply.data[y * stride + x * 4..y * stride + x * 4 + 4];
            if lsb {
                rgb.extend_from_slice(&[p[2], p[1], p[0]]);
            } else {
                rgb.extend_from_slice(&[p[1], p[2], p[3]]);
            }
        }
    }
    Ok(Image {
        width: w,
        height: h,
        rgb,
    })
}

/// The plot area's background colour in the editor (`plot.rs`).
pub const PLOT_BACKGROUND: [u8; 3] = [18, 19, 24];

/// What the motion view shows in a capture.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotStats {
    /// The bounding box of the plot background: x, y, width, height.
    pub rect: (u32, u32, u32, u32),
    /// Distinct colours inside it.
    pub colours: usize,
    /// Share of pixels clearly orange (z above rest) and clearly blue (z below rest).
    pub warm: f64,
    pub cool: f64,
}

impl std::fmt::Display for PlotStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (x, y, w, h) = self.rect;
        write!(
            f,
            "plot {w}×{h} at ({x}, {y}): {} distinct colours, {:.1} % above rest (orange), {:.1} % below (blue)",
            self.colours,
            100.0 * self.warm,
            100.0 * self.cool
        )
    }
}

/// Finds the motion view by its background colour and measures what it shows. None when no
/// plot background is visible.
pub fn plot_stats(image: &Image) -> Option<PlotStats> {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    let mut count = 0usize;
    for y in 0..image.height {
        for x in 0..image.width {
            if image.pixel(x, y) == PLOT_BACKGROUND {
                x0 = x0.min(x);
                y0 = y0.min(y);
                x1 = x1.max(x);
                y1 = y1.max(y);
                count += 1;
            }
        }
    }
    if count < 1000 {
        return None;
    }
    let mut colours = std::collections::HashSet::new();
    let (mut warm, mut cool) = (0usize, 0usize);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let [r, g, b] = image.pixel(x, y);
            colours.insert([r, g, b]);
            if r as i32 > b as i32 + 80 {
                warm += 1;
            } else if b as i32 > r as i32 + 80 {
                cool += 1;
            }
        }
    }
    let area = ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64;
    Some(PlotStats {
        rect: (x0, y0, x1 - x0 + 1, y1 - y0 + 1),
        colours: colours.len(),
        warm: warm as f64 / area,
        cool: cool as f64 / area,
    })
}

/// Whether a plot shows motion: many colours, and at least 2 % of it clearly off rest (a
/// model at rest shows only its markers in colour, about 0.1 %).
pub fn shows_motion(stats: &PlotStats) -> bool {
    stats.colours >= 200 && stats.warm + stats.cool >= 0.02
}

/// The debug `ressort-standalone` of the workspace's target folder (`cargo test` builds it
/// with `assert_process_allocs`), or the file named by `RESSORT_STANDALONE`.
pub fn standalone_path() -> PathBuf {
    if let Some(p) = std::env::var_os("RESSORT_STANDALONE") {
        return PathBuf::from(p);
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/debug/ressort-standalone")
}

/// A capture of `ressort-standalone`'s editor.
#[derive(Debug)]
pub struct Capture {
    pub image: Image,
    pub stats: Option<PlotStats>,
    /// Seconds from launch to the capture.
    pub after_s: f64,
}

/// How long a capture of a model at rest waits after the motion view first appears.
pub const SETTLE: Duration = Duration::from_secs(2);

/// Starts `standalone` on the dummy audio backend on `display` with `--model model` (and
/// `--audition` when asked), waits for its window, then captures it every half second until
/// the motion view shows motion (`until_motion`) or has been visible for [`SETTLE`], or
/// `max_wait` has passed since the window appeared. The process is stopped afterwards; an
/// early exit of the process is an error that carries its output.
pub fn capture_standalone(
    standalone: &Path,
    display: &str,
    model: &str,
    audition: bool,
    until_motion: bool,
    max_wait: Duration,
) -> Result<Capture, String> {
    let log = std::env::temp_dir().join(format!(
        "ressort-standalone-{}-{}.log",
        std::process::id(),
        display.trim_start_matches(':')
    ));
    let log_file = std::fs::File::create(&log).map_err(|e| e.to_string())?;
    let mut cmd = Command::new(standalone);
    cmd.env("DISPLAY", display)
        .args(["--model", model])
        .args(["-b", "dummy"])
        .stdout(log_file.try_clone().map_err(|e| e.to_string())?)
        .stderr(log_file);
    if audition {
        cmd.arg("--audition");
    }
    let started = Instant::now();
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("{}: {e}", standalone.display()))?;
    let output = |log: &Path| std::fs::read_to_string(log).unwrap_or_default();
    let result = (|| {
        let mut window = None;
        while started.elapsed() < max_wait + Duration::from_secs(20) {
            if let Ok(Some(status)) = child.try_wait() {
                return Err(format!(
                    "ressort-standalone exited ({status}):\n{}",
                    output(&log)
                ));
            }
            window = find_window(display, "Ressort");
            if window.is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        let Some(window) = window else {
            // Ask it to stop the way Ctrl+C does, so it reports why the editor did not open.
            let _ = Command::new("kill")
                .args(["-INT", &child.id().to_string()])
                .status();
            std::thread::sleep(Duration::from_secs(1));
            return Err(format!(
                "no window called Ressort appeared; windows: {:?}\n{}",
                window_names(display),
                output(&log)
            ));
        };
        let shown = Instant::now();
        let mut plot_seen: Option<Instant> = None;
        loop {
            std::thread::sleep(Duration::from_millis(500));
            if let Ok(Some(status)) = child.try_wait() {
                return Err(format!(
                    "ressort-standalone exited ({status}):\n{}",
                    output(&log)
                ));
            }
            let image = capture(display, window)?;
            let stats = plot_stats(&image);
            if stats.is_some() && plot_seen.is_none() {
                plot_seen = Some(Instant::now());
            }
            let done = if until_motion {
                stats.as_ref().is_some_and(shows_motion)
            } else {
                plot_seen.is_some_and(|t| t.elapsed() >= SETTLE)
            };
            if done || shown.elapsed() >= max_wait {
                return Ok(Capture {
                    image,
                    stats,
                    after_s: started.elapsed().as_secs_f64(),
                });
            }
        }
    })();
    let _ = child.kill();
    let _ = child.wait();
    let _ = std::fs::remove_file(&log);
    result
}

/// A plain top-level window to embed an editor in, as a DAW's plugin window is. Kept open
/// while the value lives.
#[derive(Debug)]
pub struct HostWindow {
    conn: x11rb::rust_connection::RustConnection,
    pub window: Window,
}

impl HostWindow {
    /// Opens a `width` × `height` window called `title` on `display`.
    pub fn open(display: &str, title: &str, width: u16, height: u16) -> Result<HostWindow, String> {
        use x11rb::protocol::xproto::{CreateWindowAux, PropMode, WindowClass};
        use x11rb::wrapper::ConnectionExt as _;
        let (conn, screen) = x11rb::connect(Some(display)).map_err(|e| e.to_string())?;
        let root = conn.setup().roots[screen].root;
        let window = conn.generate_id().map_err(|e| e.to_string())?;
        conn.create_window(
            x11rb::COPY_DEPTH_FROM_PARENT,
            window,
            root,
            0,
            0,
            width,
            height,
            0,
            WindowClass::INPUT_OUTPUT,
            x11rb::COPY_FROM_PARENT,
            &CreateWindowAux::new().background_pixel(0),
        )
        .map_err(|e| e.to_string())?;
        conn.change_property8(
            PropMode::REPLACE,
            window,
            AtomEnum::WM_NAME,
            AtomEnum::STRING,
            title.as_bytes(),
        )
        .map_err(|e| e.to_string())?;
        conn.map_window(window).map_err(|e| e.to_string())?;
        conn.flush().map_err(|e| e.to_string())?;
        Ok(HostWindow { conn, window })
    }

    /// The windows embedded in this one.
    pub fn children(&self) -> Vec<Window> {
        self.conn
            .query_tree(self.window)
            .ok()
            .and_then(|c| c.reply().ok())
            .map(|t| t.children)
            .unwrap_or_default()
    }
}
