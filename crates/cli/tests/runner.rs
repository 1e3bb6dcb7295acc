//! `histencil check` as a CI runner, each behaviour proved on lavapipe by making it happen: the
//! validation canary fails a worker whose layer is muted and passes under the runner, which pins
//! the layer's settings; shards partition the matrix; a hung case ends as `Timeout` and a crashed
//! one as `Crash` while the run goes on; a baseline turns a known failure green and an unexpected
//! pass red; flakes are told apart; a case list reruns exactly its cases; shards merge; SIGTERM
//! leaves reports of what finished; and each exit code means one thing.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_histencil");

fn command(args: &[&str]) -> Command {
    let mut c = Command::new(BIN);
    c.arg("check").args(args).env(
        "HISTENCIL_DEVICE",
        std::env::var("HISTENCIL_DEVICE").unwrap_or_else(|_| "llvmpipe".into()),
    );
    c
}

fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("histencil-runner-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `scene/case,Status` of a run's results.csv, comments left out.
fn statuses(out: &Path) -> Vec<(String, String)> {
    read(&out.join("results.csv"))
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let mut parts = l.split(',');
            (
                parts.next().unwrap().to_owned(),
                parts.next().unwrap().to_owned(),
            )
        })
        .collect()
}

/// A small slice: `brdfs-3` at 7x5 in D32S8 (the reference and 64 lighting cases).
const SLICE: [&str; 5] = ["--quick", "--scene", "brdfs-3", "--filter", "d32s8-7x5"];

#[test]
fn the_canary_fails_a_muted_worker_and_the_runner_pins_the_layer() {
    let dir = fresh_dir("canary");
    let list = dir.join("one.txt");
    std::fs::write(&list, "brdfs-3/forward-reference-d32s8-1x1\n").unwrap();
    let worker = |var: &str, value: &str| {
        let o = command(&["--worker", "--quick", "--scene", "brdfs-3", "--caselist"])
            .arg(&list)
            .arg("--out")
            .arg(dir.join("worker"))
            .env(var, value)
            .output()
            .unwrap();
        let canary = String::from_utf8_lossy(&o.stdout)
            .lines()
            .find(|l| l.contains("canary-d32_sfloat_s8_uint"))
            .unwrap_or_else(|| panic!("no canary line: {}", text(&o)))
            .to_owned();
        canary
    };
    // Unmuted: every deliberate call reported.
    let heard = worker("HISTENCIL_UNRELATED", "1");
    assert!(heard.contains("\"status\":\"Pass\""), "{heard}");
    assert!(heard.contains("12 of 12 deliberate"), "{heard}");
    // A message-id filter and a duplicate limit, as a CI machine's environment may set them.
    let filtered = worker(
        "VK_LAYER_MESSAGE_ID_FILTER",
        "VUID-VkBufferCreateInfo-size-00912",
    );
    assert!(
        filtered.contains("\"status\":\"ValidationLayerMuted\""),
        "{filtered}"
    );
    assert!(filtered.contains("0 of 12 deliberate"), "{filtered}");
    let limited = worker("VK_LAYER_DUPLICATE_MESSAGE_LIMIT", "3");
    assert!(limited.contains("3 of 12 deliberate"), "{limited}");

    // The runner under the same environment, from a folder whose vk_layer_settings.txt filters
    // the canary too: its workers see neither, and the run passes with the settings reported.
    let cwd = dir.join("cwd");
    std::fs::create_dir_all(&cwd).unwrap();
    std::fs::write(
        cwd.join("vk_layer_settings.txt"),
        "khronos_validation.message_id_filter = VUID-VkBufferCreateInfo-size-00912\n",
    )
    .unwrap();
    let out = dir.join("run");
    let json = dir.join("run.json");
    let o = command(&["--quick", "--scene", "brdfs-3", "--caselist"])
        .arg(&list)
        .arg("--out")
        .arg(&out)
        .arg("--json")
        .arg(&json)
        .current_dir(&cwd)
        .env(
            "VK_LAYER_MESSAGE_ID_FILTER",
            "VUID-VkBufferCreateInfo-size-00912",
        )
        .env("VK_LAYER_DUPLICATE_MESSAGE_LIMIT", "3")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let report: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    let settings = report["validation_settings"].to_string();
    assert!(
        settings.contains("cleared from the environment: VK_LAYER_MESSAGE_ID_FILTER="),
        "{settings}"
    );
    assert!(
        report["driver"].as_str().unwrap().contains("Mesa"),
        "{report}"
    );
    let canary = report["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "canary-d32_sfloat_s8_uint")
        .unwrap();
    assert_eq!(canary["status"], "Pass", "{canary}");
}

#[test]
fn four_shards_hold_every_case_once() {
    let list = |extra: &[&str]| -> BTreeSet<String> {
        let o = command(&[&["--list", "--quick", "--scene", "default"][..], extra].concat())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .map(str::to_owned)
            .collect()
    };
    let all = list(&[]);
    // histencil's hash shards and Mesa's interleaved fractions alike.
    for split in ["--shard K/4", "--fraction 4 --fraction-start K"] {
        let mut union = BTreeSet::new();
        for k in 1..=4 {
            let args = split.replace('K', &k.to_string());
            let args: Vec<&str> = args.split(' ').collect();
            let shard = list(&args);
            assert!(
                shard.len() > all.len() / 8,
                "{split}: {k} holds {}",
                shard.len()
            );
            for case in shard {
                assert!(union.insert(case.clone()), "{case} is in two shards");
            }
        }
        assert_eq!(union, all, "{split}");
    }
}

#[test]
fn a_hung_case_times_out_a_crashed_one_crashes_and_the_run_goes_on() {
    let dir = fresh_dir("faults");
    let hung = "stencil-x360-auto-p00-lightmap-d32s8-7x5";
    let crashed = "branching-ps3-auto-pA0-lightmap-d32s8-7x5";
    let out = dir.join("out");
    let json = dir.join("run.json");
    // 10 s: far above a real case here (a group's setup included) on a loaded 2-core machine.
    let o = command(&SLICE)
        .args(["--jobs", "2", "--timeout", "10", "--inject-fault"])
        .arg(format!("hang={hung}"))
        .arg("--out")
        .arg(&out)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let results = statuses(&out);
    let status = |name: &str| {
        results
            .iter()
            .find(|(n, _)| n == &format!("brdfs-3/{name}"))
            .map(|(_, s)| s.clone())
    };
    assert_eq!(status(hung).as_deref(), Some("Timeout"), "{results:?}");
    // The reason names what the worker was waiting on: the frame's passes, as recorded.
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains(&format!(
            "Timeout brdfs-3/{hung}: ran past the 10 s timeout; its worker was killed; it was \
             waiting on the GPU for gbuffer, lighting, tonemap"
        )),
        "{stderr}"
    );
    // Every other case ran and passed: 65 cases, one timed out.
    let passed = results.iter().filter(|(_, s)| s == "Pass").count();
    assert_eq!(passed, 64 + 2, "{results:?}");
    let report: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    assert!(report["workers"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w["end"] == "timeout"));
    assert!(report["workers"]
        .as_array()
        .unwrap()
        .iter()
        .all(|w| w["peak_mib"].as_f64().is_some_and(|m| m > 1.0)));

    // A crash: the case in flight is Crash, the rest of its batch runs in a new worker.
    let out = dir.join("crash");
    let o = command(&SLICE)
        .args(["--jobs", "2", "--inject-fault"])
        .arg(format!("crash={crashed}"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let results = statuses(&out);
    let crashes: Vec<&(String, String)> = results.iter().filter(|(_, s)| s != "Pass").collect();
    assert_eq!(
        crashes,
        [&(format!("brdfs-3/{crashed}"), "Crash".to_owned())],
        "{results:?}"
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("it was waiting on the GPU for gbuffer, lighting, tonemap"),
        "{stderr}"
    );

    // A crash tearing the device down, after every case reported, fails the run as the worker's
    // own device row: the cases all passed, the verdict does not.
    // A few cases suffice: the crash comes after the last.
    let few = [
        "--quick",
        "--scene",
        "brdfs-3",
        "--filter",
        "ps3-auto-p00-lightmap-d32s8-7x5",
    ];
    let o = command(&few)
        .args(["--jobs", "1", "--inject-fault", "crash=device/teardown-d32"])
        .arg("--out")
        .arg(dir.join("teardown"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let teardown = statuses(&dir.join("teardown"));
    assert!(
        teardown
            .iter()
            .any(|(n, s)| n.starts_with("device/worker-") && s == "Crash"),
        "{teardown:?}"
    );
    let passed = teardown
        .iter()
        .filter(|(n, s)| n.starts_with("brdfs-3/") && s == "Pass");
    assert_eq!(passed.count(), 4, "{teardown:?}");

    // --max-fails stops the run at the first failing case, and says so.
    let json = dir.join("max-fails.json");
    let o = command(&SLICE)
        .args(["--jobs", "1", "--max-fails", "1", "--inject-fault"])
        .arg(format!("crash={crashed}"))
        .arg("--out")
        .arg(dir.join("max-fails"))
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let report: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    assert!(
        report["incomplete"]
            .as_str()
            .unwrap()
            .contains("--max-fails"),
        "{report}"
    );

    // failures.csv is a baseline: with it, the same crash is expected and the run is green.
    let baseline = dir.join("baseline.txt");
    std::fs::copy(out.join("failures.csv"), &baseline).unwrap();
    let o = command(&SLICE)
        .args(["--jobs", "2", "--inject-fault"])
        .arg(format!("crash={crashed}"))
        .arg("--baseline")
        .arg(&baseline)
        .arg("--out")
        .arg(dir.join("expected"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(text(&o).contains("1 ExpectedFail"), "{}", text(&o));

    // Without the fault, the baseline's crash is an unexpected pass: red unless allowed.
    let unexpected = |allow: bool| {
        let mut c = command(&SLICE);
        c.arg("--baseline")
            .arg(&baseline)
            .arg("--out")
            .arg(dir.join("fixed"));
        if allow {
            c.arg("--allow-unexpected-pass");
        }
        c.output().unwrap()
    };
    let o = unexpected(false);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("1 UnexpectedPass"), "{}", text(&o));
    assert_eq!(unexpected(true).status.code(), Some(0));

    // A flake pattern makes the crash a flake; a case list reruns exactly the failures.
    let flakes = dir.join("flakes.txt");
    std::fs::write(
        &flakes,
        "# known to crash now and then\nbranching-ps3-auto\n",
    )
    .unwrap();
    let o = command(&SLICE)
        .args(["--inject-fault"])
        .arg(format!("crash={crashed}"))
        .arg("--flakes")
        .arg(&flakes)
        .arg("--caselist")
        .arg(out.join("failures.csv"))
        .arg("--out")
        .arg(dir.join("flaky"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let flaky = statuses(&dir.join("flaky"));
    let matrix: Vec<_> = flaky
        .iter()
        .filter(|(n, _)| n.starts_with("brdfs-3/"))
        .collect();
    assert_eq!(
        matrix,
        [&(format!("brdfs-3/{crashed}"), "Flake".to_owned())]
    );
}

#[test]
fn shards_merge_into_one_report() {
    let dir = fresh_dir("merge");
    let mut jsons = Vec::new();
    for k in 1..=2 {
        let json = dir.join(format!("shard-{k}.json"));
        let o = command(&["--quick", "--scene", "brdfs-3", "--filter", "d32s8-1x1"])
            .arg("--shard")
            .arg(format!("{k}/2"))
            .arg("--out")
            .arg(dir.join(format!("shard-{k}")))
            .arg("--json")
            .arg(&json)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        jsons.push(json);
    }
    let (junit, json) = (dir.join("merged.xml"), dir.join("merged.json"));
    let o = Command::new(BIN)
        .args(["check", "merge"])
        .args(&jsons)
        .arg("--junit")
        .arg(&junit)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let merged: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    let names: BTreeSet<String> = merged["cases"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["scene"] == "brdfs-3")
        .map(|c| c["name"].as_str().unwrap().to_owned())
        .collect();
    assert_eq!(names.len(), 1 + 64, "{names:?}");
    assert_eq!(merged["shards"], serde_json::json!(["1/2", "2/2"]));
    assert!(read(&junit).contains("<testsuite name=\"brdfs-3\" tests=\"65\""));
    // A shard given twice, or one missing (its job died before writing its report), is refused.
    for (shards, why) in [
        (vec![&jsons[0], &jsons[0]], "twice"),
        (vec![&jsons[0]], "shard 2/2 missing"),
    ] {
        let o = Command::new(BIN)
            .args(["check", "merge"])
            .args(shards)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        assert!(text(&o).contains(why), "{}", text(&o));
    }
}

#[test]
fn sigterm_leaves_reports_of_what_finished() {
    let dir = fresh_dir("sigterm");
    let (out, junit, json) = (dir.join("out"), dir.join("junit.xml"), dir.join("run.json"));
    // The sixth case hangs and the timeout is long: the run cannot finish on its own.
    let mut child = command(&SLICE)
        .args(["--jobs", "1", "--inject-fault", "hang=stencil-ps3-always"])
        .arg("--out")
        .arg(&out)
        .arg("--junit")
        .arg(&junit)
        .arg("--json")
        .arg(&json)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let results = out.join("results.csv");
    let start = std::time::Instant::now();
    while statuses_if_any(&results) < 3 {
        assert!(start.elapsed().as_secs() < 120, "no results streamed");
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
    // SAFETY: `kill` takes plain integers; the pid is our own child's, not yet waited for, so
    // it cannot have been reused by another process.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let code = child.wait().unwrap().code();
    assert_eq!(code, Some(5), "stopped early with nothing failing: exit 5");
    let xml = read(&junit);
    assert!(xml.ends_with("</testsuites>\n"), "{xml}");
    assert!(xml.contains("name=\"incomplete\""), "{xml}");
    let report: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    let finished = report["cases"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["scene"] == "brdfs-3")
        .count();
    assert!(finished >= 3, "{report}");
    assert_eq!(
        xml.matches("<testcase ").count(),
        report["cases"].as_array().unwrap().len()
    );
}

fn statuses_if_any(results: &Path) -> usize {
    std::fs::read_to_string(results)
        .map(|t| t.lines().filter(|l| l.starts_with("brdfs-3/")).count())
        .unwrap_or(0)
}

#[test]
fn exit_codes_tell_usage_no_cases_and_bad_lists_apart() {
    let dir = fresh_dir("codes");
    let o = command(&["--quick", "--scene", "brdfs-3", "--filter", "no-such-case"])
        .arg("--out")
        .arg(dir.join("none"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(4), "{}", text(&o));
    let bad = dir.join("bad-baseline.txt");
    std::fs::write(&bad, "brdfs-3/x,ValidationLayerMuted\n").unwrap();
    // A job meant for another driver refuses to run.
    let o = command(&SLICE)
        .args(["--expect-driver", "Mesa 99.9"])
        .arg("--out")
        .arg(dir.join("driver"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("not the `Mesa 99.9`"), "{}", text(&o));
    for args in [
        vec!["--baseline", bad.to_str().unwrap()],
        vec!["--shard", "3/2"],
        vec!["--inject-fault", "melt"],
    ] {
        let o = command(&[&SLICE[..], &args].concat()).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
        assert!(!text(&o).contains("panicked"), "{}", text(&o));
    }
}

/// The gtest face: `--gtest_list_tests` prints only what deqp-runner's list parser takes (a
/// `Group.` line, then indented names that hold no dot), one test per case `--list` prints;
/// `--gtest_filter` runs exactly the named tests here, with googletest's lines on stdout and an
/// empty stderr; a case list or baseline in gtest spelling selects what the `scene/case`
/// spelling does.
#[test]
fn the_gtest_face_lists_runs_and_maps_names_one_to_one() {
    let args = ["--quick", "--scene", "default", "--filter", "d32s8-7x5"];
    let o = command(&[&args[..], &["--gtest_list_tests"]].concat())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let listing = String::from_utf8_lossy(&o.stdout).into_owned();
    let mut tests = Vec::new();
    let mut group = None;
    for line in listing.lines() {
        if let Some(name) = line.strip_prefix("  ") {
            assert!(!name.contains('.') && !name.contains('-'), "{line}");
            tests.push(format!("{}{name}", group.as_deref().unwrap()));
        } else {
            assert!(line.ends_with('.') && !line.contains(' '), "{line}");
            group = Some(line.to_owned());
        }
    }
    let o = command(&[&args[..], &["--list"]].concat())
        .output()
        .unwrap();
    let full: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(str::to_owned)
        .collect();
    assert_eq!(tests.len(), full.len());
    assert!(tests.len() > 30, "{listing}");

    let dir = fresh_dir("gtest");
    let out = dir.join("out");
    let chosen = [tests[0].as_str(), tests[5].as_str()].join(":");
    let o = command(
        &[
            &args[..],
            &[
                &format!("--gtest_filter={chosen}"),
                "--out",
                out.to_str().unwrap(),
            ],
        ]
        .concat(),
    )
    .output()
    .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(o.stderr.is_empty(), "{}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    for test in [&tests[0], &tests[5]] {
        assert!(
            stdout.contains(&format!("[ RUN      ] {test}\n")),
            "{stdout}"
        );
        assert!(
            stdout.contains(&format!("[       OK ] {test} (")),
            "{stdout}"
        );
    }
    assert_eq!(stdout.matches("[ RUN      ]").count(), 2, "{stdout}");

    // A failing test: FAILED, exit 1, its reason indented after the line, no bracket in it.
    let o = command(
        &[
            &args[..],
            &[
                "--gtest_filter=default.stencil_ps3_auto_p00_lightmap_d32s8_7x5",
                "--out",
                out.to_str().unwrap(),
                "--inject-fault",
                "flaky=stencil-ps3-auto-p00-lightmap-d32s8-7x5",
            ],
        ]
        .concat(),
    )
    .output()
    .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let after: Vec<&str> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("[  FAILED  ]"))
        .skip(1)
        .collect();
    assert!(after[0].starts_with("    default/stencil-ps3"), "{stdout}");
    assert!(after.iter().all(|l| !l.contains('[')), "{stdout}");

    // Case lists and baselines in gtest spelling.
    let gtest_list = dir.join("gtest.txt");
    std::fs::write(&gtest_list, format!("{}\n{}\n", tests[0], tests[5])).unwrap();
    let full_list = dir.join("full.txt");
    std::fs::write(&full_list, format!("{}\n{}\n", full[0], full[5])).unwrap();
    let listed = |list: &Path| {
        let o = command(&[&args[..], &["--list", "--caselist", list.to_str().unwrap()]].concat())
            .output()
            .unwrap();
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    assert_eq!(listed(&gtest_list), listed(&full_list));
    assert_eq!(listed(&gtest_list).lines().count(), 2);
}

/// A fault aimed at a case that never waits on the GPU (the forward reference, rendered with
/// its group's setup) strikes that case, and one aimed at a case that stops before it waits (a
/// first flaky run) never passes to the next: each fault lands on the case it names.
#[test]
fn an_injected_fault_lands_on_the_case_it_names() {
    let dir = fresh_dir("fault-aim");
    let out = dir.join("out");
    let o = command(&SLICE)
        .args(["--jobs", "1", "--inject-fault"])
        .arg("crash=forward-reference-d32s8-7x5")
        .args([
            "--inject-fault",
            "flaky=stencil-native-auto-p00-lightmap-d32s8-7x5",
        ])
        .args([
            "--inject-fault",
            "hang=stencil-native-auto-p00-lightmap-d32s8-7x5",
        ])
        .args(["--timeout", "10"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let failing: Vec<(String, String)> = statuses(&out)
        .into_iter()
        .filter(|(_, s)| s != "Pass")
        .collect();
    assert_eq!(
        failing,
        [
            (
                "brdfs-3/forward-reference-d32s8-7x5".to_owned(),
                "Crash".to_owned()
            ),
            // Its first run fails by the flake and ends before the armed hang strikes; the
            // hang does not pass to the next case (which would time out), it strikes only the
            // rerun of its own.
            (
                "brdfs-3/stencil-native-auto-p00-lightmap-d32s8-7x5".to_owned(),
                "Fail".to_owned()
            ),
        ],
        "{}",
        text(&o)
    );
}
