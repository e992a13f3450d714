//! Links the plugin library with `-z nodelete` on ELF targets: once a host has loaded it, a
//! `dlclose` leaves it mapped.
//!
//! Rust's standard library registers a pthread key whose destructor lives in the plugin
//! library the first time a host thread calls `std::thread::current()` inside it (nice-plug's
//! CLAP wrapper does when an instance is created). If the host unloads the library and that
//! thread exits later, glibc calls the destructor at an unmapped address and the host crashes
//! (rust-lang/rust#91979). The end-to-end tests, which create and drop instances on many
//! threads, hit it one run in four under load.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if matches!(
        os.as_str(),
        "linux" | "android" | "freebsd" | "netbsd" | "openbsd"
    ) {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-z,nodelete");
    }
}
