//! `ressort-starts`: starts `ressort-standalone` again and again, each time under a fresh
//! private Xvfb, and counts the starts whose editor window never appears.
//!
//! ```text
//! ressort-starts [--standalone PATH] [--starts N] [--watch S] [--keep DIR] [-- STANDALONE ARGS…]
//! ```
//!
//! A start succeeds when a window called `Ressort` appears and the process is still alive
//! `--watch` seconds later (default 1: past the GL context creation and the first frames);
//! it fails when the process exits first, or when no window appears within 20 s (the process
//! is then asked to stop with SIGINT, then killed). Each start runs in its own folder under
//! `--keep` (default `target/starts`) with its output in `log`; the folders of failed starts
//! are kept, so a core dump (`ulimit -c unlimited`, the kernel's `core` pattern) lands next to
//! the log. The standalone's own arguments (default `-b dummy`) follow `--`.
//!
//! The last line is `starts=N failures=K crashes=C no_window=W`; the exit status is 0 when
//! every start succeeded, 1 otherwise, 2 on usage errors. `scripts/starts.sh` runs it on the
//! release build under load and prints the backtraces of the crashes.

use ressort_tests::screen::{find_window, standalone_path, ChildGuard, Xvfb};
use std::os::unix::process::ExitStatusExt;
use std::path::PathBuf;
use std::process::{Command, ExitStatus};
use std::time::{Duration, Instant};

enum Outcome {
    Ok,
    Exited(ExitStatus, bool),
    NoWindow,
    NoServer,
}

fn main() -> std::process::ExitCode {
    std::process::ExitCode::from(run())
}

fn usage() -> u8 {
    eprintln!(
        "usage: ressort-starts [--standalone PATH] [--starts N] [--watch S] [--keep DIR] [-- STANDALONE ARGS…]"
    );
    2
}

fn run() -> u8 {
    let mut standalone = standalone_path();
    let mut starts = 200u32;
    let mut watch = 1.0f64;
    let mut keep = PathBuf::from("target/starts");
    let mut extra: Vec<String> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let Some(value) = (match a.as_str() {
            "--" => {
                extra.extend(args.by_ref());
                break;
            }
            "--standalone" | "--starts" | "--watch" | "--keep" => args.next(),
            _ => return usage(),
        }) else {
            return usage();
        };
        match a.as_str() {
            "--standalone" => standalone = PathBuf::from(value),
            "--keep" => keep = PathBuf::from(value),
            "--starts" => match value.parse() {
                Ok(n) => starts = n,
                Err(_) => return usage(),
            },
            _ => match value.parse() {
                Ok(s) => watch = s,
                Err(_) => return usage(),
            },
        }
    }
    if extra.is_empty() {
        extra = vec!["-b".into(), "dummy".into()];
    }
    let standalone = match standalone.canonicalize() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("ressort-starts: {}: {e}", standalone.display());
            return 2;
        }
    };
    let (mut failures, mut crashes, mut no_window) = (0u32, 0u32, 0u32);
    let began = Instant::now();
    for i in 1..=starts {
        let dir = keep.join(format!("start-{i:04}"));
        let _ = std::fs::remove_dir_all(&dir);
        if let Err(e) = std::fs::create_dir_all(&dir) {
            eprintln!("ressort-starts: {}: {e}", dir.display());
            return 2;
        }
        let outcome = start_once(&standalone, &extra, &dir, Duration::from_secs_f64(watch));
        let what = match &outcome {
            Outcome::Ok => {
                let _ = std::fs::remove_dir_all(&dir);
                continue;
            }
            Outcome::Exited(status, after_window) => {
                if status.signal().is_some() {
                    crashes += 1;
                }
                format!(
                    "exited {} its window appeared: {status}",
                    if *after_window { "after" } else { "before" }
                )
            }
            Outcome::NoWindow => {
                no_window += 1;
                "no window within 20 s".to_string()
            }
            Outcome::NoServer => "Xvfb did not start".to_string(),
        };
        failures += 1;
        let log = std::fs::read_to_string(dir.join("log")).unwrap_or_default();
        println!("start {i}: {what} ({})", dir.display());
        for line in log.lines().take(20) {
            println!("  | {line}");
        }
    }
    println!("{starts} starts in {:.0} s", began.elapsed().as_secs_f64());
    println!("starts={starts} failures={failures} crashes={crashes} no_window={no_window}");
    u8::from(failures > 0)
}

fn start_once(standalone: &PathBuf, extra: &[String], dir: &PathBuf, watch: Duration) -> Outcome {
    let Some(x) = Xvfb::start(1280, 800) else {
        return Outcome::NoServer;
    };
    let Ok(log) = std::fs::File::create(dir.join("log")) else {
        return Outcome::NoServer;
    };
    let mut cmd = Command::new(standalone);
    cmd.current_dir(dir)
        .env("DISPLAY", x.display())
        .env("RUST_BACKTRACE", "1")
        .args(extra)
        .stdout(log.try_clone().expect("log file"))
        .stderr(log);
    let Ok(mut child) = ChildGuard::spawn(&mut cmd) else {
        return Outcome::NoServer;
    };
    let started = Instant::now();
    let mut seen: Option<Instant> = None;
    loop {
        if let Ok(Some(status)) = child.try_wait() {
            return Outcome::Exited(status, seen.is_some());
        }
        match seen {
            None if find_window(x.display(), "Ressort").is_some() => seen = Some(Instant::now()),
            None if started.elapsed() > Duration::from_secs(20) => {
                // Ask it to stop the way Ctrl+C does, so its log says why.
                child.interrupt();
                std::thread::sleep(Duration::from_secs(2));
                return Outcome::NoWindow;
            }
            Some(t) if t.elapsed() >= watch => return Outcome::Ok,
            _ => {}
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}
