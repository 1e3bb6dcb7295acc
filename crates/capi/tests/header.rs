//! `include/histencil.h` is what cbindgen generates from this crate now: a change to the C API
//! that is not in the committed header fails here (`HISTENCIL_BLESS=1` rewrites it).

use std::path::Path;

#[test]
fn the_committed_header_is_the_one_the_source_generates() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config =
        cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen reads the crate")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8");
    let path = crate_dir.join("include/histencil.h");
    if std::env::var_os("HISTENCIL_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/histencil.h differs from what the source generates: run \
         HISTENCIL_BLESS=1 cargo test -p histencil-capi --test header, and commit it"
    );
}
