//! `ressort-screenshot`: starts `ressort-standalone` with a model under a private Xvfb,
//! captures the editor window as a PNG and says what the motion view shows.
//!
//! ```text
//! ressort-screenshot [--model NAME] [--out FILE.png] [--standalone PATH] [--seconds S] [--at-rest]
//!                    [--click X,Y | --type TEXT]...
//! ```
//!
//! Each `--click X,Y` clicks the editor at those window coordinates and each `--type TEXT`
//! types into the widget that has the keyboard (lower-case letters, digits, spaces), in the
//! order given, once the capture would have been taken; the capture follows two seconds later.
//!
//! By default the model is struck every second (`--audition`) and the capture is taken as soon
//! as the motion view shows motion (within S seconds of the window appearing, default 20);
//! `--at-rest` does not strike and captures two seconds after the motion view appears. Exit status 0 when the plot shows motion (or, with
//! `--at-rest`, whatever it shows), 1 when it does not, 2 on errors.

//!
//! The Xvfb and the standalone stop with this program on every path: errors return through
//! `main` so their guards drop, and the kernel stops them if it is killed (see
//! `screen::ChildGuard`).

use ressort_tests::screen::{
    capture_standalone_after_clicks, shows_motion, standalone_path, Action, Xvfb,
};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

fn main() -> ExitCode {
    ExitCode::from(run())
}

const USAGE: &str = "usage: ressort-screenshot [--model NAME] [--out FILE.png] [--standalone PATH] [--seconds S] [--at-rest] [--click X,Y | --type TEXT]...";

fn run() -> u8 {
    let mut model = "mesh-25x20".to_string();
    let mut out = None;
    let mut standalone = standalone_path();
    let mut seconds = 20.0;
    let mut at_rest = false;
    let mut actions: Vec<Action> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--at-rest" {
            at_rest = true;
            continue;
        }
        if !matches!(
            a.as_str(),
            "--model" | "--out" | "--standalone" | "--seconds" | "--click" | "--type"
        ) {
            eprintln!("{USAGE}");
            return 2;
        }
        let Some(value) = args.next() else {
            eprintln!("ressort-screenshot: {a} needs a value");
            return 2;
        };
        match a.as_str() {
            "--model" => model = value,
            "--out" => out = Some(PathBuf::from(value)),
            "--standalone" => standalone = PathBuf::from(value),
            "--click" => match value
                .split_once(',')
                .and_then(|(x, y)| Some((x.trim().parse().ok()?, y.trim().parse().ok()?)))
            {
                Some((x, y)) => actions.push(Action::Click(x, y)),
                None => {
                    eprintln!("ressort-screenshot: --click takes X,Y (window pixels)");
                    return 2;
                }
            },
            "--type" => actions.push(Action::Type(value)),
            _ => match value.parse() {
                Ok(s) => seconds = s,
                Err(_) => {
                    eprintln!("ressort-screenshot: --seconds takes a number");
                    return 2;
                }
            },
        }
    }
    let out = out.unwrap_or_else(|| {
        PathBuf::from(format!(
            "target/screenshots/editor-{}{}.png",
            model.replace(['/', '.'], "_"),
            if at_rest { "-at-rest" } else { "" }
        ))
    });
    let Some(x) = Xvfb::start(1280, 800) else {
        eprintln!("ressort-screenshot: Xvfb could not be started (is the xvfb package installed?)");
        return 2;
    };
    let capture = match capture_standalone_after_clicks(
        &standalone,
        x.display(),
        &model,
        !at_rest,
        !at_rest,
        Duration::from_secs_f64(seconds),
        &actions,
    ) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("ressort-screenshot: {e}");
            return 2;
        }
    };
    drop(x);
    if let Err(e) = capture.image.save_png(&out) {
        eprintln!("ressort-screenshot: {e}");
        return 2;
    }
    println!(
        "wrote {} ({}×{}, {:.1} s after launch)",
        out.display(),
        capture.image.width,
        capture.image.height,
        capture.after_s
    );
    match &capture.stats {
        Some(s) => println!("{s}"),
        None => println!("no motion view found in the capture"),
    }
    let moving = capture.stats.as_ref().is_some_and(shows_motion);
    println!(
        "motion view: {}",
        if moving {
            "shows motion"
        } else {
            "blank or at rest"
        }
    );
    u8::from(!moving && !at_rest)
}
