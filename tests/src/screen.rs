//! Looking at the editor: a private X server (Xvfb, with Mesa's software OpenGL), window
//! capture through the X protocol, PNG output, and a measure of how much a plot shows.
//!
//! Used by `tests/editor.rs` and by `ressort-screenshot` (see `scripts/screenshot.sh`).

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};
use x11rb::connection::Connection;
use x11rb::protocol::xproto::{AtomEnum, ConnectionExt, ImageFormat, ImageOrder, Window};

/// A child process that does not outlive its parent: it is stopped (SIGTERM, SIGKILL if it is
/// still there 3 s later) and reaped when the guard is dropped, and the kernel sends it SIGTERM
/// when the thread that spawned it ends, so a parent that exits through
/// `std::process::exit`, a panic that aborts, Ctrl+C or any other signal leaves nothing behind.
/// SIGTERM rather than SIGKILL lets Xvfb remove its lock file and socket.
///
/// The signal follows the spawning *thread* (`PR_SET_PDEATHSIG`): spawn from a thread that
/// lives as long as the child is wanted (a test's own thread, or `main`).
#[derive(Debug)]
pub struct ChildGuard(Child);

impl ChildGuard {
    pub fn spawn(cmd: &mut Command) -> std::io::Result<ChildGuard> {
        // SAFETY: the closure runs between fork and exec and calls only async-signal-safe
        // functions (prctl, getppid, kill on itself).
        let parent = std::process::id() as libc::pid_t;
        unsafe {
            cmd.pre_exec(move || {
                if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM as libc::c_ulong) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                // The parent may have died before the prctl: then nobody will send it.
                if libc::getppid() != parent {
                    libc::kill(libc::getpid(), libc::SIGKILL);
                }
                Ok(())
            });
        }
        cmd.spawn().map(ChildGuard)
    }

    pub fn try_wait(&mut self) -> std::io::Result<Option<ExitStatus>> {
        self.0.try_wait()
    }

    /// Sends SIGINT, as Ctrl+C in a terminal does (nothing once the child has been reaped).
    pub fn interrupt(&mut self) {
        self.signal(libc::SIGINT);
    }

    fn signal(&mut self, signal: libc::c_int) {
        if let Ok(None) = self.0.try_wait() {
            // SAFETY: kill has no memory-safety preconditions. The child has not been reaped
            // (try_wait just said it is running), so the pid is still its own.
            unsafe { libc::kill(self.0.id() as libc::pid_t, signal) };
        }
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        self.signal(libc::SIGTERM);
        let deadline = Instant::now() + Duration::from_secs(3);
        while let Ok(None) = self.0.try_wait() {
            if Instant::now() > deadline {
                let _ = self.0.kill();
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = self.0.wait();
    }
}

enum StartError {
    /// Xvfb cannot be run.
    NoXvfb,
    /// This server did not come up on its display (another one took it first).
    Lost,
}

/// Whether display `n` is taken: its lock file names a live process, or its socket exists
/// without a lock file. A lock left by a server that was killed is stale: the next server on
/// that display removes it.
fn display_taken(n: u32) -> bool {
    match std::fs::read_to_string(format!("/tmp/.X{n}-lock")) {
        Ok(pid) => match pid.trim().parse::<libc::pid_t>() {
            Ok(pid) if pid > 0 => {
                // SAFETY: signal 0 only checks that the process exists.
                let alive = unsafe { libc::kill(pid, 0) } == 0;
                alive || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
            }
            _ => true,
        },
        Err(_) => Path::new(&format!("/tmp/.X11-unix/X{n}")).exists(),
    }
}

/// An Xvfb server on a free display, stopped when dropped (and killed by the kernel when the
/// thread that started it ends: see [`ChildGuard`]).
#[derive(Debug)]
pub struct Xvfb {
    // Held for its drop, which stops the server.
    _server: ChildGuard,
    // The `-displayfd` pipe, open while the server runs (see `start_on`).
    _ready: std::fs::File,
    display: String,
}

impl Xvfb {
    /// Starts Xvfb with a 24-bit screen of `width` × `height` on the first display number
    /// that is free. None when Xvfb is not installed or does not come up.
    pub fn start(width: u32, height: u32) -> Option<Xvfb> {
        // Tests start servers in parallel: one at a time within a process. Other processes
        // (another test binary, `ressort-screenshot`) may pick the same number meanwhile:
        // the server that loses exits, and only the winner writes its number to the
        // `-displayfd` pipe, so a server is never mistaken for another process's one.
        static STARTING: std::sync::Mutex<()> = std::sync::Mutex::new(());
        let _one_at_a_time = STARTING.lock().unwrap_or_else(|e| e.into_inner());
        for n in 90..200u32 {
            if display_taken(n) {
                continue;
            }
            match Xvfb::start_on(n, width, height) {
                Ok(x) => return Some(x),
                Err(StartError::NoXvfb) => return None,
                Err(StartError::Lost) => continue,
            }
        }
        None
    }

    fn start_on(n: u32, width: u32, height: u32) -> Result<Xvfb, StartError> {
        use std::io::Read;
        use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
        let mut fds = [0; 2];
        // SAFETY: `fds` has room for the two descriptors pipe2 writes.
        if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
            return Err(StartError::NoXvfb);
        }
        // SAFETY: pipe2 succeeded, so both descriptors are open and owned by nobody else.
        let (ready_read, ready_write) =
            unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
        let write_fd = ready_write.as_raw_fd();
        let mut cmd = Command::new("Xvfb");
        // `-noreset`: by default the server resets when its last client disconnects and hangs
        // up on a client that connects meanwhile. Every `find_window` poll is a client, so the
        // standalone's first connection could meet a reset: its editor then failed with
        // "XOpenDisplay() failed" and nice-plug waited forever without a window (14 of 762
        // loaded starts, `scripts/starts.sh`).
        cmd.arg(format!(":{n}"))
            .args(["-screen", "0", &format!("{width}x{height}x24")])
            .args(["-nolisten", "tcp", "-noreset"])
            .args(["-displayfd", &write_fd.to_string()])
            .stdout(Stdio::null())
            .stderr(Stdio::null());
        // SAFETY: fcntl is async-signal-safe; the descriptor is open until the parent drops
        // `ready_write` after the spawn.
        unsafe {
            cmd.pre_exec(move || {
                if libc::fcntl(write_fd, libc::F_SETFD, 0) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = ChildGuard::spawn(&mut cmd).map_err(|_| StartError::NoXvfb)?;
        drop(ready_write);
        // The server writes its display number and a newline (two writes) once it accepts
        // connections; a server that lost the display to another one exits, and the pipe
        // reports end of file. The reading end stays open as long as the server runs: a
        // server that writes into a closed pipe exits.
        let mut ready = std::fs::File::from(ready_read);
        let mut written = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(20);
        while !written.ends_with(b"\n") {
            let left = deadline.saturating_duration_since(Instant::now());
            let mut poll = libc::pollfd {
                fd: ready.as_raw_fd(),
                events: libc::POLLIN,
                revents: 0,
            };
            // SAFETY: one valid pollfd.
            if left.is_zero() || unsafe { libc::poll(&mut poll, 1, left.as_millis() as i32) } != 1 {
                return Err(StartError::Lost);
            }
            let mut byte = [0u8; 16];
            match ready.read(&mut byte) {
                Ok(0) | Err(_) => return Err(StartError::Lost),
                Ok(len) => written.extend_from_slice(&byte[..len]),
            }
        }
        if String::from_utf8_lossy(&written).trim() != n.to_string() {
            return Err(StartError::Lost);
        }
        Ok(Xvfb {
            _server: child,
            _ready: ready,
            display: format!(":{n}"),
        })
    }

    /// The `DISPLAY` value: `:93`.
    pub fn display(&self) -> &str {
        &self.display
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

/// Clicks the left button at (`x`, `y`) in `window` through the XTEST extension, as a user's
/// pointer would.
pub fn click(display: &str, window: Window, x: i16, y: i16) -> Result<(), String> {
    use x11rb::protocol::xproto::{BUTTON_PRESS_EVENT, BUTTON_RELEASE_EVENT, MOTION_NOTIFY_EVENT};
    use x11rb::protocol::xtest::ConnectionExt as _;
    use x11rb::wrapper::ConnectionExt as _;
    let (conn, screen) = x11rb::connect(Some(display)).map_err(|e| e.to_string())?;
    let root = conn.setup().roots[screen].root;
    let at = conn
        .translate_coordinates(window, root, x, y)
        .map_err(|e| e.to_string())?
        .reply()
        .map_err(|e| e.to_string())?;
    let fake = |kind: u8, detail: u8| {
        conn.xtest_fake_input(kind, detail, 0, root, at.dst_x, at.dst_y, 0)
            .map_err(|e| e.to_string())
    };
    fake(MOTION_NOTIFY_EVENT, 0)?;
    conn.flush().map_err(|e| e.to_string())?;
    std::thread::sleep(Duration::from_millis(100));
    fake(BUTTON_PRESS_EVENT, 1)?;
    conn.flush().map_err(|e| e.to_string())?;
    std::thread::sleep(Duration::from_millis(80));
    fake(BUTTON_RELEASE_EVENT, 1)?;
    conn.sync().map_err(|e| e.to_string())?;
    Ok(())
}

/// Types `text` (lower-case letters, digits, spaces and common punctuation: what the keyboard
/// map has without a modifier) through the XTEST extension, into the window that has the
/// keyboard focus.
pub fn type_text(display: &str, text: &str) -> Result<(), String> {
    use x11rb::protocol::xproto::{KEY_PRESS_EVENT, KEY_RELEASE_EVENT};
    use x11rb::protocol::xtest::ConnectionExt as _;
    use x11rb::wrapper::ConnectionExt as _;
    let (conn, screen) = x11rb::connect(Some(display)).map_err(|e| e.to_string())?;
    let root = conn.setup().roots[screen].root;
    let (min, max) = (conn.setup().min_keycode, conn.setup().max_keycode);
    let map = conn
        .get_keyboard_mapping(min, max - min + 1)
        .map_err(|e| e.to_string())?
        .reply()
        .map_err(|e| e.to_string())?;
    let per = map.keysyms_per_keycode.max(1) as usize;
    for c in text.chars() {
        // Latin-1 keysyms are the characters' codes; the first keysym of a key is unshifted.
        let code = map
            .keysyms
            .chunks(per)
            .position(|syms| syms.first() == Some(&(c as u32)))
            .map(|i| min + i as u8)
            .ok_or_else(|| format!("no unshifted key types {c:?}"))?;
        for kind in [KEY_PRESS_EVENT, KEY_RELEASE_EVENT] {
            conn.xtest_fake_input(kind, code, 0, root, 0, 0, 0)
                .map_err(|e| e.to_string())?;
            conn.flush().map_err(|e| e.to_string())?;
            std::thread::sleep(Duration::from_millis(40));
        }
    }
    conn.sync().map_err(|e| e.to_string())?;
    Ok(())
}

/// What a screenshot does in the editor before its capture.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// A left click at window pixels.
    Click(i16, i16),
    /// Keys typed into the focused widget.
    Type(String),
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
    capture_standalone_after_clicks(
        standalone,
        display,
        model,
        audition,
        until_motion,
        max_wait,
        &[],
    )
}

/// [`capture_standalone`], then each of `actions` (clicks at window coordinates, typed text;
/// in order, half a second apart) once the capture would have been taken, and capturing two
/// seconds later.
pub fn capture_standalone_after_clicks(
    standalone: &Path,
    display: &str,
    model: &str,
    audition: bool,
    until_motion: bool,
    max_wait: Duration,
    actions: &[Action],
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
    let mut child =
        ChildGuard::spawn(&mut cmd).map_err(|e| format!("{}: {e}", standalone.display()))?;
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
            child.interrupt();
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
                if !actions.is_empty() {
                    for action in actions {
                        match action {
                            Action::Click(x, y) => click(display, window, *x, *y)?,
                            Action::Type(text) => type_text(display, text)?,
                        }
                        std::thread::sleep(Duration::from_millis(500));
                    }
                    std::thread::sleep(SETTLE);
                    let image = capture(display, window)?;
                    return Ok(Capture {
                        stats: plot_stats(&image),
                        image,
                        after_s: started.elapsed().as_secs_f64(),
                    });
                }
                return Ok(Capture {
                    image,
                    stats,
                    after_s: started.elapsed().as_secs_f64(),
                });
            }
        }
    })();
    drop(child);
    let _ = std::fs::remove_file(&log);
    result
}

/// The environment variable that hands a test's child process its private display.
const DISPLAY_ENV: &str = "RESSORT_TEST_DISPLAY";

/// Runs the calling test `test` in a child process (this test binary, `--exact`) that gets a
/// private Xvfb of `width` × `height` in `DISPLAY`, so the X server outlives every X11
/// connection the plugin opened (Xlib exits the process when its server goes away). In the
/// child it returns the display; in the parent it runs the child, prints its output, asserts
/// that it ran the test and passed, and returns None: the parent's test is then done.
pub fn in_private_display(test: &str, width: u32, height: u32) -> Option<String> {
    if let Ok(display) = std::env::var(DISPLAY_ENV) {
        return Some(display);
    }
    let x = Xvfb::start(width, height)
        .expect("Xvfb starts (scripts/setup.sh installs the xvfb package)");
    let out = Command::new(std::env::current_exe().expect("the test binary"))
        .args([test, "--exact", "--nocapture", "--test-threads=1"])
        .env(DISPLAY_ENV, x.display())
        .env("DISPLAY", x.display())
        .output()
        .expect("run the test in a child process");
    let stdout = String::from_utf8_lossy(&out.stdout);
    print!("{stdout}");
    eprint!("{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        out.status.success(),
        "{test} failed in its child process: {}",
        out.status
    );
    // The child ran this very test: a renamed test would otherwise match nothing and pass.
    assert!(
        stdout.contains(&format!("test {test} ... "))
            && stdout.contains("test result: ok. 1 passed"),
        "the child process did not run `{test}`"
    );
    None
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

    /// The first window embedded in this one (an editor's), waiting up to `timeout` for it.
    pub fn embedded(&self, timeout: Duration) -> Option<Window> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(&child) = self.children().first() {
                return Some(child);
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
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
