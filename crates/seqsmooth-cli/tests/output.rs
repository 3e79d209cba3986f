//! Output files are replaced only on success (`io::Output`, the plots): a failing command leaves
//! an existing `-o FILE` as it was and no partial or temporary file beside it; standard output
//! streams the rows before the error as before. A symbolic link stays a link (its file gets the
//! rows), and what is not a regular file (a named pipe, a device such as `/dev/null`) is
//! written in place, not replaced by a regular file.

mod common;
use common::*;
use std::path::{Path, PathBuf};

/// A fresh, empty directory for one test.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = tmp(&format!("output-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The names of the files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `rows` good rows `t = k, y = k` (header first), then a row whose time goes backwards.
fn input_failing_after(rows: usize) -> String {
    let mut text = String::from("t,y\n");
    for k in 0..rows {
        text += &format!("{k},{k}\n");
    }
    text + "0,1\n"
}

#[test]
fn filter_error_after_rows_leaves_the_old_file() {
    // 300 rows pass the 101-row hold-back, so rows are written before the error is found.
    let dir = fresh_dir("filter-late");
    let input = dir.join("in.csv");
    std::fs::write(&input, input_failing_after(300)).unwrap();
    let out = dir.join("out.csv");
    std::fs::write(&out, "old contents\n").unwrap();
    let args = ["filter", "--kind", "expanding", "--degree", "1"];
    let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
    let r = run(&[&args[..], &[i, "-o", o]].concat(), "");
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(r.stderr.contains("line 302"), "{}", r.stderr);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old contents\n");
    assert_eq!(listing(&dir), ["in.csv", "out.csv"]);
    // No file at all when there was none.
    std::fs::remove_file(&out).unwrap();
    assert_eq!(run(&[&args[..], &[i, "-o", o]].concat(), "").code, 1);
    assert_eq!(listing(&dir), ["in.csv"]);
    // Standard output still streams every row before the bad one.
    let r = run(&args, &input_failing_after(300));
    assert_eq!(r.code, 1);
    assert_eq!(r.stdout.lines().count(), 301, "header and 300 rows");
}

#[test]
fn filter_success_replaces_the_file_keeping_its_permissions() {
    let dir = fresh_dir("filter-ok");
    let out = dir.join("out.csv");
    std::fs::write(&out, "old contents\n").unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
    }
    let args = ["filter", "--kind", "expanding", "--degree", "1", "-o"];
    let r = run(
        &[&args[..], &[out.to_str().unwrap()]].concat(),
        "t,y\n0,1\n1,3\n",
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("t,y,d0,d1\n0,1,,\n1,3,3,2\n"), "{text}");
    assert_eq!(listing(&dir), ["out.csv"]);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }
}

#[test]
fn smooth_and_plot_errors_leave_the_old_file() {
    let dir = fresh_dir("smooth");
    let out = dir.join("s.csv");
    std::fs::write(&out, "old\n").unwrap();
    let o = out.to_str().unwrap();
    let r = run(
        &["smooth", "--degree", "1", "--window", "3", "-o", o],
        "t,y\n0,1\n1,2\n1,3\n",
    );
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old\n");
    assert_eq!(listing(&dir), ["s.csv"]);
    // A plot that cannot be written (no such directory) leaves nothing behind either.
    let png = dir.join("no-dir").join("x.png");
    let r = run(
        &["demo", "--plot", png.with_extension("").to_str().unwrap()],
        "",
    );
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(r.stderr.contains("cannot write the plot"), "{}", r.stderr);
    // The message names the file asked for, in words (no temporary name, no debug text).
    assert!(
        r.stderr.contains("x.png': No such file or directory") && !r.stderr.contains("at path"),
        "{}",
        r.stderr
    );
    assert_eq!(listing(&dir), ["s.csv"]);
}

#[cfg(unix)]
#[test]
fn a_symbolic_link_stays_a_link() {
    use std::os::unix::fs::symlink;
    let dir = fresh_dir("symlink");
    let (link, real) = (dir.join("link.csv"), dir.join("real.csv"));
    std::fs::write(&real, "old\n").unwrap();
    symlink("real.csv", &link).unwrap();
    let args = ["filter", "--kind", "expanding", "--degree", "1", "-o"];
    let input = "t,y\n0,1\n1,3\n";
    let expected = ok(&args[..5], input);
    for out in [&link, &dir.join("dangling.csv")] {
        if out != &link {
            symlink("later.csv", out).unwrap();
        }
        let r = run(&[&args[..], &[out.to_str().unwrap()]].concat(), input);
        assert_eq!(r.code, 0, "{}", r.stderr);
        assert!(std::fs::symlink_metadata(out).unwrap().is_symlink());
        assert_eq!(std::fs::read_to_string(out).unwrap(), expected);
    }
    assert_eq!(std::fs::read_to_string(&real).unwrap(), expected);
    assert_eq!(
        listing(&dir),
        ["dangling.csv", "later.csv", "link.csv", "real.csv"]
    );
    // A plot through a link too.
    let (svg, target) = (dir.join("p.svg"), dir.join("target.svg"));
    symlink("target.svg", &svg).unwrap();
    let r = run(&["plot", "-o", svg.to_str().unwrap()], &expected);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(std::fs::symlink_metadata(&svg).unwrap().is_symlink());
    assert!(std::fs::read_to_string(&target).unwrap().contains("<svg"));
}

/// A named pipe made by `mkfifo`, read by a thread into a string.
#[cfg(target_os = "linux")]
fn fifo_reader(path: &Path) -> std::thread::JoinHandle<Vec<u8>> {
    let made = std::process::Command::new("mkfifo").arg(path).status();
    assert!(made.unwrap().success(), "mkfifo {}", path.display());
    let path = path.to_path_buf();
    std::thread::spawn(move || std::fs::read(path).unwrap())
}

#[cfg(target_os = "linux")]
#[test]
fn a_named_pipe_is_written_in_place() {
    use std::os::unix::fs::FileTypeExt;
    let dir = fresh_dir("fifo");
    let input = "t,y\n0,1\n1,3\n2,4\n";
    let is_fifo = |p: &Path| std::fs::metadata(p).unwrap().file_type().is_fifo();
    let cases: [(&str, &[&str]); 2] = [
        ("f.csv", &["filter", "--kind", "expanding", "--degree", "1"]),
        ("s.csv", &["smooth", "--degree", "1", "--window", "3"]),
    ];
    for (name, args) in cases {
        let fifo = dir.join(name);
        let reader = fifo_reader(&fifo);
        let r = run(&[args, &["-o", fifo.to_str().unwrap()]].concat(), input);
        assert_eq!(r.code, 0, "{}", r.stderr);
        // Before joining: a pipe replaced by a file leaves its reader waiting for ever.
        assert!(is_fifo(&fifo), "{name} is still a named pipe");
        let got = String::from_utf8(reader.join().unwrap()).unwrap();
        assert_eq!(got, ok(args, input), "{name}");
    }
    let fifo = dir.join("p.svg");
    let reader = fifo_reader(&fifo);
    let filtered = ok(cases[0].1, input);
    let r = run(&["plot", "-o", fifo.to_str().unwrap()], &filtered);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(String::from_utf8(reader.join().unwrap())
        .unwrap()
        .contains("<svg"));
    assert!(is_fifo(&fifo));
    assert_eq!(listing(&dir), ["f.csv", "p.svg", "s.csv"]);
}

#[test]
fn a_closed_pipe_ends_quietly() {
    // As `seqsmooth filter big.csv | head -1`: the reader goes away after one line.
    use std::io::{BufRead, BufReader};
    use std::process::{Command, Stdio};
    let dir = fresh_dir("pipe");
    let input = dir.join("big.csv");
    let mut text = String::from("t,y\n");
    for k in 0..200_000 {
        text += &format!("{k},{}\n", k % 7);
    }
    std::fs::write(&input, text).unwrap();
    let args = [
        "filter", "--kind", "fading", "--degree", "2", "--theta", "0.9",
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
        .args(args)
        .arg(&input)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert_eq!(first, "t,y,d0,d1,d2\n");
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(String::from_utf8_lossy(&out.stderr), "");
}
