//! A file of histencil's shaders compiled for an engine's BRDFs and hooks, written at the
//! engine's build (`histencil shaders --brdfs DIR --hooks DIR --out FILE`) and read at run time:
//! what a C or C++ engine ships so that neither its build nor its users need cargo or glslc.
//! A Rust engine has the same at its build from histencil-build.
//!
//! The file holds the BRDF folder's files (its `brdfs.toml` and GLSL, which the set is read
//! from again and which an engine's own shaders include), which hook files the engine gave, and
//! every module that evaluates a BRDF or calls a hook, as SPIR-V. It is read as untrusted
//! input: its header, version and checksum first, every length against what is left, every
//! name confined, each module held to the stage histencil's own of that name has, and the BRDF
//! folder read through the manifest's checks again; anything else is refused with the reason.
//!
//! The format, in order: the line `histencil shaders`, `format 1`, `histencil <version>` (the
//! modules are this version's shaders: another's are refused), `checksum <16 hex digits>`
//! (FNV-1a, 64 bits, of every byte after that line), `hooks <files>` (`-` for none), then
//! entries `<brdfs|spirv> <name> <length>` each followed by its bytes and a newline, then `end`.

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Mutex, OnceLock};

use histencil_brdf::BrdfSet;

use crate::brdf_modules::{compile_with_hooks, modules_of, BrdfModules, Scratch};
use crate::gpu::device::spirv_bindings::reflect_bindings;
use crate::lighting::hooks::spirv_words;

const HEAD: &str = "histencil shaders\nformat 1\n";
/// The largest file read back: histencil's modules for 24 BRDFs with hooks are a few MiB.
const MAX_BYTES: usize = 64 << 20;
/// The manifest's name in a BRDF folder.
const MANIFEST: &str = "brdfs.toml";

/// A shader file read back: the set (its folder a private copy, removed with this value), the
/// modules compiled for it, and which hook files the engine gave.
#[derive(Debug)]
pub struct ShaderFile {
    /// The BRDF set, read from the file's copy of the engine's folder.
    pub set: BrdfSet,
    /// Every module, compiled for the set and the hooks. They live as long as the process (as
    /// [`crate::compile_brdf_set`]'s do); the same file read twice gives the same modules.
    pub modules: &'static BrdfModules,
    /// The hook files the engine gave (histencil-build's `HOOK_FILES`); empty for none.
    pub hooks: Vec<String>,
    /// The copy of the BRDF folder the set reads its GLSL from, removed with this value.
    _folder: Option<Scratch>,
}

/// FNV-1a, 64 bits: enough to tell a truncated or damaged file, not a forged one (a file an
/// engine ships beside its binary is as trusted as the binary).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Every module of `modules` by the field name [`modules_of`] reads it back with.
fn named_modules(modules: &BrdfModules) -> Vec<(&'static str, &'static [u8])> {
    let mut out: Vec<_> = modules.light.named().to_vec();
    out.extend([
        ("forward", modules.forward),
        ("lightmap", modules.lightmap),
        ("lightmap_directional", modules.lightmap_directional),
        ("alpha_object", modules.alpha_object),
        ("particle", modules.particle),
        ("brdf_eval", modules.brdf_eval),
    ]);
    out
}

/// histencil's own module of each name: what a module read back must match in stage.
fn builtin_named() -> HashMap<&'static str, &'static [u8]> {
    named_modules(BrdfModules::builtin()).into_iter().collect()
}

/// A name the file may carry for a BRDF folder's file: the manifest or a relative `.glsl` path
/// of plain parts, the manifest's own confinement.
fn confined(name: &str) -> bool {
    let plain = |part: &str| {
        !part.is_empty()
            && part != "."
            && part != ".."
            && part
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"_-.".contains(&b))
    };
    (name == MANIFEST || name.ends_with(".glsl")) && name.split('/').all(plain)
}

/// Compiles histencil's shaders for the BRDF folder `brdfs` (histencil's own BRDFs without one)
/// and the hook folder `hooks` (histencil's G-buffer and no shadows without one) and writes them
/// to `out`, whole or not at all (a file beside it, renamed over `out` when complete).
/// Returns how many modules it holds.
///
/// # Errors
/// A message: the folder refused (manifest, GLSL, includes), glslc's refusal naming the
/// engine's file and line, `out` not writable.
pub fn write_shader_file(
    brdfs: Option<&Path>,
    hooks: Option<&Path>,
    out: &Path,
) -> Result<usize, String> {
    let set = match brdfs {
        Some(dir) => BrdfSet::load(dir).map_err(|e| e.to_string())?,
        None => BrdfSet::default(),
    };
    let modules = compile_with_hooks(&set, hooks)?;
    let mut body = String::from("hooks");
    let given: Vec<&str> = histencil_build::HOOK_FILES
        .into_iter()
        .filter(|f| hooks.is_some_and(|h| h.join(f).is_file()))
        .collect();
    body += &if given.is_empty() {
        " -\n".to_owned()
    } else {
        format!(" {}\n", given.join(" "))
    };
    let mut body = body.into_bytes();
    let mut entry = |kind: &str, name: &str, bytes: &[u8]| {
        body.extend(format!("{kind} {name} {}\n", bytes.len()).bytes());
        body.extend(bytes);
        body.push(b'\n');
    };
    if let Some(folder) = set.folder() {
        let manifest = folder.join(MANIFEST);
        let text = std::fs::read(&manifest).map_err(|e| format!("{}: {e}", manifest.display()))?;
        entry("brdfs", MANIFEST, &text);
        for (relative, path) in histencil_build::engine_files(folder).map_err(|e| e.to_string())? {
            let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            entry("brdfs", &relative, &bytes);
        }
    }
    let named = named_modules(modules);
    for (name, spirv) in &named {
        entry("spirv", name, spirv);
    }
    body.extend(b"end\n");
    let mut file = format!(
        "{HEAD}histencil {}\nchecksum {:016x}\n",
        env!("CARGO_PKG_VERSION"),
        fnv1a(&body)
    )
    .into_bytes();
    file.extend(body);
    let partial = out.with_extension(format!("partial-{}", std::process::id()));
    std::fs::write(&partial, &file)
        .and_then(|()| std::fs::rename(&partial, out))
        .map_err(|e| {
            let _ = std::fs::remove_file(&partial);
            format!("{}: {e}", out.display())
        })?;
    Ok(named.len())
}

/// Reads the line at the start of `rest` (without its newline), leaving `rest` after it.
fn line<'a>(rest: &mut &'a [u8], what: &str) -> Result<&'a str, String> {
    let end = rest
        .iter()
        .position(|b| *b == b'\n')
        .ok_or_else(|| format!("the file ends inside {what}"))?;
    let text = std::str::from_utf8(&rest[..end]).map_err(|_| format!("{what} is not text"))?;
    *rest = &rest[end + 1..];
    Ok(text)
}

/// What the file's body holds: its hook files, the BRDF folder's files and the modules.
struct Body<'a> {
    hooks: Vec<String>,
    files: Vec<(&'a str, &'a [u8])>,
    spirv: HashMap<&'a str, &'a [u8]>,
}

/// Parses `bytes` as a shader file of this version, without compiling or writing anything.
fn parse(bytes: &[u8]) -> Result<Body<'_>, String> {
    if bytes.len() > MAX_BYTES {
        return Err(format!(
            "{} bytes, past the {MAX_BYTES} a shader file may hold",
            bytes.len()
        ));
    }
    let mut rest = bytes
        .strip_prefix(HEAD.as_bytes())
        .ok_or("not a histencil shader file of format 1 (written by `histencil shaders`)")?;
    let version = line(&mut rest, "the version line")?;
    let ours = format!("histencil {}", env!("CARGO_PKG_VERSION"));
    if version != ours {
        return Err(format!(
            "written by `{version}`, and this is {ours}: its modules are another version's \
             shaders; write it again with this version's `histencil shaders`"
        ));
    }
    let checksum = line(&mut rest, "the checksum line")?;
    let want = checksum
        .strip_prefix("checksum ")
        .and_then(|h| u64::from_str_radix(h, 16).ok())
        .ok_or("no checksum line")?;
    if fnv1a(rest) != want {
        return Err("its checksum does not match its contents: the file is damaged or cut".into());
    }
    let hooks_line = line(&mut rest, "the hooks line")?;
    let hooks: Vec<String> = match hooks_line.strip_prefix("hooks ") {
        Some("-") => Vec::new(),
        Some(names) => names.split(' ').map(str::to_owned).collect(),
        None => return Err("no hooks line".into()),
    };
    if let Some(h) = hooks
        .iter()
        .find(|h| !histencil_build::HOOK_FILES.contains(&h.as_str()))
    {
        return Err(format!("it names hook file `{h}`, which histencil has not"));
    }
    let (mut files, mut spirv) = (Vec::new(), HashMap::new());
    let known = builtin_named();
    loop {
        let header = line(&mut rest, "an entry's line")?;
        if header == "end" {
            break;
        }
        let mut parts = header.split(' ');
        let (Some(kind), Some(name), Some(len), None) =
            (parts.next(), parts.next(), parts.next(), parts.next())
        else {
            return Err(format!("`{header}` is not an entry's line"));
        };
        let len: usize = len
            .parse()
            .map_err(|_| format!("`{header}`: the length is not a number"))?;
        if len >= rest.len() || rest[len] != b'\n' {
            return Err(format!("`{header}`: the file ends inside the entry"));
        }
        let (content, after) = rest.split_at(len);
        rest = &after[1..];
        match kind {
            "brdfs" if confined(name) => files.push((name, content)),
            "brdfs" => return Err(format!("`{name}` is not a BRDF folder's file")),
            "spirv" if !known.contains_key(name) => {
                return Err(format!("`{name}` is not a histencil module"))
            }
            "spirv" => {
                if spirv.insert(name, content).is_some() {
                    return Err(format!("module `{name}` given twice"));
                }
            }
            other => return Err(format!("`{other}` is not a kind of entry")),
        }
    }
    if !rest.is_empty() {
        return Err("bytes after its end".into());
    }
    Ok(Body {
        hooks,
        files,
        spirv,
    })
}

/// Each module held to histencil's own of its name: SPIR-V, of the same stages.
fn check_stages(spirv: &HashMap<&str, &[u8]>) -> Result<(), String> {
    let builtin = builtin_named();
    for (name, bytes) in spirv {
        let stages = |b: &[u8]| {
            spirv_words(b)
                .and_then(|w| reflect_bindings(&w))
                .map(|r| r.stages)
        };
        let theirs = stages(bytes).map_err(|e| format!("module `{name}`: {e}"))?;
        let ours = stages(builtin[name]).expect("histencil's own modules are SPIR-V");
        if theirs != ours {
            return Err(format!(
                "module `{name}` is of stage {theirs:?}, where histencil's is {ours:?}"
            ));
        }
    }
    Ok(())
}

/// Reads a shader file [`write_shader_file`] wrote (with this version of histencil).
///
/// # Errors
/// A message naming what is wrong: not a shader file, another version's, damaged or cut, a
/// module missing or of the wrong stage, the BRDF folder refused as `brdfs.toml` would be.
pub fn read_shader_file(path: &Path) -> Result<ShaderFile, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let at = |e: String| format!("{}: {e}", path.display());
    let body = parse(&bytes).map_err(at)?;
    check_stages(&body.spirv).map_err(at)?;
    let (set, folder) = if body.files.is_empty() {
        (BrdfSet::default(), None)
    } else {
        let folder = Scratch::new().map_err(|e| at(format!("a folder for its BRDFs: {e}")))?;
        for (name, content) in &body.files {
            folder.write(name, content).map_err(at)?;
        }
        let set = BrdfSet::load(&folder.0).map_err(|e| at(e.to_string()))?;
        (set, Some(folder))
    };
    // One set of modules per distinct file, for the process (a `LightModules` is 'static).
    static READ: OnceLock<Mutex<HashMap<u64, &'static BrdfModules>>> = OnceLock::new();
    let cache = READ.get_or_init(Default::default);
    let key = fnv1a(&bytes);
    let cached = cache
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .get(&key)
        .copied();
    let modules = match cached {
        Some(modules) => modules,
        None => {
            let module = |name: &str| {
                body.spirv
                    .get(name)
                    .map(|b| &*Box::leak(b.to_vec().into_boxed_slice()))
            };
            let missing = named_modules(BrdfModules::builtin())
                .into_iter()
                .find(|(name, _)| !body.spirv.contains_key(name));
            if let Some((name, _)) = missing {
                return Err(at(format!("it lacks module `{name}`")));
            }
            let made = modules_of(&set, module).expect("every module present");
            let made: &'static BrdfModules = Box::leak(Box::new(made));
            cache
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .insert(key, made);
            made
        }
    };
    Ok(ShaderFile {
        set,
        modules,
        hooks: body.hooks,
        _folder: folder,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_confined_as_the_manifest_confines_its_paths() {
        for good in ["brdfs.toml", "toon.glsl", "lib/ramp.glsl"] {
            assert!(confined(good), "{good}");
        }
        for bad in [
            "../x.glsl",
            "/etc/x.glsl",
            "a//b.glsl",
            "x.toml",
            "a/./b.glsl",
            "x y.glsl",
        ] {
            assert!(!confined(bad), "{bad}");
        }
    }

    #[test]
    fn damaged_cut_and_foreign_files_are_refused_with_their_reason() {
        let body = b"hooks -\nend\n".to_vec();
        let file = |version: &str, body: &[u8], sum: u64| {
            let mut f = format!("{HEAD}histencil {version}\nchecksum {sum:016x}\n").into_bytes();
            f.extend(body);
            f
        };
        let ours = env!("CARGO_PKG_VERSION");
        assert!(parse(&file(ours, &body, fnv1a(&body))).is_ok());
        let refused = |bytes: &[u8], words: &str| match parse(bytes) {
            Err(e) => assert!(e.contains(words), "`{e}` should say `{words}`"),
            Ok(_) => panic!("accepted, should say `{words}`"),
        };
        refused(b"PNG", "not a histencil shader file");
        refused(&file("0.0.0", &body, fnv1a(&body)), "write it again");
        refused(&file(ours, &body, fnv1a(&body) ^ 1), "damaged or cut");
        let cut = file(ours, &body, fnv1a(&body));
        refused(&cut[..cut.len() - 3], "damaged or cut");
        for (bad, words) in [
            (
                &b"hooks -\nspirv forward 99\nxx\nend\n"[..],
                "ends inside the entry",
            ),
            (
                b"hooks -\nbrdfs ../x.glsl 1\nx\nend\n",
                "not a BRDF folder's file",
            ),
            (
                b"hooks -\nspirv nothing 1\nx\nend\n",
                "not a histencil module",
            ),
            (b"hooks a.glsl\nend\n", "hook file `a.glsl`"),
            (b"hooks -\nend\nmore", "after its end"),
            (b"hooks -\nspirv forward x\n", "not a number"),
        ] {
            refused(&file(ours, bad, fnv1a(bad)), words);
        }
    }

    /// A file of histencil's own modules, its body mutated at random (bytes flipped, cut,
    /// repeated) and its checksum made to match again, so that every mutation reaches the
    /// parser and the SPIR-V checks behind the checksum: each is refused or read, never a panic.
    #[test]
    fn mutated_files_past_the_checksum_are_refused_or_read_never_a_panic() {
        let mut body = b"hooks -\n".to_vec();
        for (name, spirv) in named_modules(BrdfModules::builtin()) {
            body.extend(format!("spirv {name} {}\n", spirv.len()).bytes());
            body.extend(spirv);
            body.push(b'\n');
        }
        body.extend(b"end\n");
        let file = |body: &[u8]| {
            let head = format!(
                "{HEAD}histencil {}\nchecksum {:016x}\n",
                env!("CARGO_PKG_VERSION"),
                fnv1a(body)
            );
            [head.as_bytes(), body].concat()
        };
        let unmutated = file(&body);
        let whole = parse(&unmutated).expect("the unmutated file reads");
        check_stages(&whole.spirv).expect("histencil's own modules");
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = |below: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % below as u64) as usize
        };
        let (mut refused, mut read) = (0, 0);
        for _ in 0..1500 {
            let mut mutated = body.clone();
            for _ in 0..1 + next(4) {
                let at = next(mutated.len());
                match next(4) {
                    0 => mutated[at] ^= 1 << next(8),
                    1 => mutated[at] = b"0123456789 \nx"[next(13)],
                    2 => mutated.truncate(at),
                    _ => {
                        let piece = mutated[at..(at + 1 + next(64)).min(mutated.len())].to_vec();
                        mutated.splice(at..at, piece);
                    }
                }
                if mutated.is_empty() {
                    break;
                }
            }
            match parse(&file(&mutated)).and_then(|b| check_stages(&b.spirv)) {
                Ok(()) => read += 1,
                Err(_) => refused += 1,
            }
        }
        assert!(refused > 500 && read > 0, "{refused} refused, {read} read");
    }
}
