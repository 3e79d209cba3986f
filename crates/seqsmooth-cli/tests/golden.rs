//! The command's outputs, byte for byte, against golden files made by the binary before the
//! command's re-layout (`tests/fixtures/golden/make.sh`, which lists how): standard output,
//! standard error, the exit code, and the files a case writes (`*.out` names in its arguments).

use std::path::{Path, PathBuf};
use std::process::Command;

fn golden() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/golden")
}

#[test]
fn outputs_are_byte_identical_to_the_golden_files() {
    let dir = golden();
    let work = std::env::temp_dir().join(format!("seqsmooth-golden-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy();
        if path.extension().is_some_and(|e| e == "csv") && !name.starts_with("written-") {
            std::fs::copy(&path, work.join(path.file_name().unwrap())).unwrap();
        }
    }
    let cases = std::fs::read_to_string(dir.join("cases.txt")).unwrap();
    let mut checked = 0;
    for line in cases.lines().filter(|l| !l.is_empty()) {
        let (name, args) = line.split_once('|').unwrap();
        let args: Vec<&str> = args.split_whitespace().collect();
        // Cases read the outputs of earlier ones (plot): those are the golden files.
        let written: Vec<&str> = args
            .windows(2)
            .filter(|w| w[0] == "-o")
            .map(|w| w[1])
            .collect();
        for a in args
            .iter()
            .filter(|a| a.ends_with(".out") && !written.contains(a))
        {
            std::fs::copy(dir.join(a), work.join(a)).unwrap();
        }
        for w in &written {
            let _ = std::fs::remove_file(work.join(w));
        }
        let out = Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
            .args(&args)
            .current_dir(&work)
            .output()
            .unwrap();
        let want = |ext: &str| std::fs::read(dir.join(format!("{name}.{ext}"))).unwrap();
        assert_eq!(out.stdout, want("out"), "{name}: standard output");
        assert_eq!(out.stderr, want("err"), "{name}: standard error");
        let code = out.status.code().unwrap().to_string();
        assert_eq!(
            code.as_bytes(),
            want("code").trim_ascii(),
            "{name}: exit code"
        );
        // Files the case writes (-o NAME.out): compared too.
        for w in written {
            let got = std::fs::read(work.join(w)).unwrap_or_default();
            assert!(got == std::fs::read(dir.join(w)).unwrap(), "{name}: {w}");
        }
        checked += 1;
    }
    assert!(checked >= 30, "{checked} cases");
    let _ = std::fs::remove_dir_all(&work);
}
