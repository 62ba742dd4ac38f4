//! The shared library's SONAME: `libtrisort_export.so.0`, as libtrisort's (capi/build.rs).

fn main() {
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libtrisort_export.so.0");
    }
}
