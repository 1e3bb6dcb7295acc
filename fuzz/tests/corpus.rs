//! Every corpus seed and every input the fuzzer once crashed on, replayed through its target:
//! a crash found is fixed at its root and its input kept in `fuzz/regressions/TARGET`, so that
//! it stays fixed in every `cargo test`, without AFL++.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

#[test]
fn every_seed_and_every_crash_found_returns_without_a_defect() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (mut replayed, mut defects) = (0, Vec::new());
    for (name, target) in histencil_fuzz::TARGETS {
        for folder in ["corpus", "regressions"] {
            let dir = root.join(folder).join(name);
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            for entry in entries {
                let path = entry.unwrap().path();
                let data = std::fs::read(&path).unwrap();
                if catch_unwind(AssertUnwindSafe(|| target(&data))).is_err() {
                    defects.push(path.display().to_string());
                }
                replayed += 1;
            }
        }
    }
    assert!(replayed >= 13, "only {replayed} inputs found");
    assert!(defects.is_empty(), "defects on {defects:#?}");
}
