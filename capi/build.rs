//! The shared library's SONAME: `libtrisort.so.0` (the file cargo writes is
//! `libtrisort_capi.so`; scripts/install-capi.sh installs it under the SONAME's name). It
//! changes only with an ABI change that is not an addition (see `TRISORT_ABI_VERSION`).

fn main() {
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libtrisort.so.0");
    }
}
