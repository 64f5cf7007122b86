//! The committed C header `include/aloft.h` is what cbindgen generates from `src/lib.rs` now.
//! Regenerate it with `ALOFT_BLESS_HEADER=1 cargo test -p aloft-ffi --test header`.

use std::path::Path;

#[test]
fn committed_header_is_up_to_date() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    // `with_src` parses this crate's source only: no `cargo metadata`, no dependencies.
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen generates the header");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8 header");
    let path = dir.join("include/aloft.h");
    if std::env::var_os("ALOFT_BLESS_HEADER").is_some() {
        std::fs::write(&path, &generated).expect("write include/aloft.h");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "crates/ffi/include/aloft.h is stale: regenerate it with \
         `ALOFT_BLESS_HEADER=1 cargo test -p aloft-ffi --test header` and commit it"
    );
}
