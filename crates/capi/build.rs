//! The shared library's soname, as a C user's linker records it: `libhistencil.so.<major>`
//! (tools/c-install installs the file under that name, with the development link beside it).
fn main() {
    let major = std::env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets the version");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libhistencil.so.{major}");
    }
}
