//! Process isolation: tests that can crash the process run in a child of their own.

/// The environment variable that tells a test binary it runs one isolated test.
pub const CHILD_ENV: &str = "RESSORT_E2E_CHILD";

/// Runs a test in its own process, for tests that can crash the process (an abort inside the
/// plugin ends every test sharing the process). Call it first in the test:
///
/// ```no_run
/// # fn f() {
/// if !ressort_tests::run_isolated("my_test") {
///     return; // the parent: the child ran the test and passed
/// }
/// // … the test body, running in the child …
/// # }
/// ```
///
/// In the parent it re-runs the test binary filtered to `test_name`, forwards its output and
/// panics (with the signal, if any) when the child fails; it returns `false`. In the child it
/// returns `true`.
pub fn run_isolated(test_name: &str) -> bool {
    if std::env::var(CHILD_ENV).as_deref() == Ok(test_name) {
        return true;
    }
    let output = run_child(test_name, CHILD_ENV, test_name);
    let stdout = String::from_utf8_lossy(&output.stdout);
    print!("{stdout}");
    // The child's stderr can hold thousands of plugin log lines: keep its head, its tail
    // (where a crash's backtrace is) and every panic message in between.
    let stderr = String::from_utf8_lossy(&output.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    let (head, tail) = (20, 150);
    if lines.len() > head + tail + 1 {
        let middle = &lines[head..lines.len() - tail];
        let panics: Vec<&&str> = middle.iter().filter(|l| l.contains("panicked")).collect();
        for line in &lines[..head] {
            eprintln!("{line}");
        }
        eprintln!(
            "[… {} lines of the isolated test's stderr left out, but these panics …]",
            middle.len() - panics.len()
        );
        for line in panics {
            eprintln!("{line}");
        }
        eprintln!("[…]");
        for line in &lines[lines.len() - tail..] {
            eprintln!("{line}");
        }
    } else {
        eprint!("{stderr}");
    }
    assert!(
        stdout.contains("running 1 test"),
        "the isolated run did not find test {test_name:?}"
    );
    if !output.status.success() {
        panic!(
            "{test_name} failed in its own process: {}",
            describe_exit(&output.status)
        );
    }
    false
}

pub(crate) fn describe_exit(status: &std::process::ExitStatus) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(signal) = status.signal() {
            let name = match signal {
                6 => " (SIGABRT: the process aborted)",
                9 => " (SIGKILL)",
                11 => " (SIGSEGV)",
                _ => "",
            };
            return format!("killed by signal {signal}{name}");
        }
    }
    format!("{status}")
}

/// Runs the test `test_name` of this test binary alone in a child process, with the
/// environment variable `var` set to `value` (how the child knows what to do), and returns what
/// it printed.
pub fn run_child(test_name: &str, var: &str, value: &str) -> std::process::Output {
    let exe = std::env::current_exe().expect("the test binary's path");
    std::process::Command::new(exe)
        .args([test_name, "--exact", "--nocapture", "--test-threads=1"])
        .env(var, value)
        .output()
        .expect("spawn the child test")
}
