//! `histencil shaders` writes the file a C or C++ engine ships (its BRDFs' and hooks' shaders,
//! compiled at its build) and it reads back whole; a hook that does not compile is an error
//! naming the engine's file and line, and leaves no file behind.

use std::path::Path;
use std::process::Command;

fn histencil(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_histencil"))
        .args(args)
        .output()
        .expect("run histencil");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn fresh(name: &str) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn shaders_writes_an_engines_brdfs_and_hooks_into_one_file_that_reads_back() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let (brdfs, hooks) = (
        root.join("examples/brdfs"),
        root.join("examples/hooks/two_target"),
    );
    let out = fresh("shaders").join("engine.shaders");
    let (ok, stdout, stderr) = histencil(&[
        "shaders",
        "--brdfs",
        brdfs.to_str().unwrap(),
        "--hooks",
        hooks.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("14 modules"), "{stdout}");
    let file = histencil_vk::read_shader_file(&out).unwrap();
    assert_eq!(file.hooks, ["surface_decode.glsl", "light_visibility.glsl"]);
    let names: Vec<&str> = file.set.ids().iter().map(|b| b.name()).collect();
    assert!(
        names.contains(&"toon") && names.contains(&"charlie_sheen"),
        "{names:?}"
    );
    assert_eq!(file.modules.light.brdf_names, names.as_slice());
}

#[test]
fn a_hook_that_does_not_compile_names_its_line_and_leaves_no_file() {
    let hooks = fresh("broken-hooks");
    std::fs::write(
        hooks.join("light_visibility.glsl"),
        "#include \"frame.glsl\"\n#include \"surface.glsl\"\nfloat light_visibility(uint i, \
         Light light, Surface s) {\n    return undeclared;\n}\n",
    )
    .unwrap();
    let out = fresh("broken-out").join("engine.shaders");
    let (ok, _, stderr) = histencil(&[
        "shaders",
        "--hooks",
        hooks.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(stderr.contains("light_visibility.glsl:4"), "{stderr}");
    assert!(stderr.contains("undeclared"), "{stderr}");
    assert!(!out.exists(), "a half-written file");
    let leftovers = std::fs::read_dir(out.parent().unwrap()).unwrap().count();
    assert_eq!(leftovers, 0, "nothing beside it either");
    // A folder with no hook file is refused as such.
    let empty = fresh("no-hooks");
    let (ok, _, stderr) = histencil(&[
        "shaders",
        "--hooks",
        empty.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(stderr.contains("holds neither"), "{stderr}");
}
