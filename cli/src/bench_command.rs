//! `luxeval bench --command "ARGS"`: whole-process figures of real commands, the ones a user
//! waits for (the quick start, an irradiance or falloff command's start-up, a falloff
//! map against `--device cpu`, a streamed emission run's peak memory). The throughput rows time
//! calls inside one process on a prepared scene; these time `luxeval ARGS --device gpu` and
//! `luxeval ARGS --device cpu` as child processes of this binary, alternately, from spawn to
//! exit, with each child's peak resident set.

use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::Instant;

use crate::exit::{CliResult, Failure};

/// One command on one device: every run's wall time and the largest peak RSS among them.
#[derive(serde::Serialize)]
pub struct CommandRow {
    /// The arguments after `luxeval`, as given (`--device` is added by the bench).
    pub command: String,
    /// "gpu" or "cpu": the `--device` the child ran with.
    pub device: &'static str,
    /// Wall time of each run, spawn to exit, in the order run.
    pub runs_seconds: Vec<f64>,
    pub median_seconds: f64,
    /// The largest peak resident set of the runs (the child's `ru_maxrss`), bytes; absent where
    /// the platform does not report it.
    pub peak_rss_bytes: Option<u64>,
}

/// The arguments of one `--command`: split at whitespace (no quoting), checked before any run.
pub fn parse(args: &str) -> Result<Vec<String>, String> {
    let words: Vec<String> = args.split_whitespace().map(str::to_string).collect();
    if words.is_empty() {
        return Err("--command: expected a luxeval command line, e.g. \"falloff scene.usda --res 128,128 -o map.exr\"".into());
    }
    if let Some(w) = words
        .iter()
        .find(|w| *w == "--device" || w.starts_with("--device="))
    {
        return Err(format!(
            "--command {args:?}: remove {w}: the bench runs the command with --device gpu and --device cpu itself"
        ));
    }
    if words[0] == "bench" {
        return Err(format!(
            "--command {args:?}: a bench cannot time another bench"
        ));
    }
    Ok(words)
}

/// Times each command `runs` times on each device in `devices`, alternating, so that a machine
/// whose speed drifts affects both alike.
pub fn measure(
    commands: &[Vec<String>],
    devices: &[&'static str],
    runs: usize,
) -> CliResult<Vec<CommandRow>> {
    let exe = std::env::current_exe()
        .map_err(|e| Failure::runtime(format!("finding this executable to re-run it: {e}")))?;
    let runs = runs.max(1);
    let mut rows: Vec<CommandRow> = Vec::new();
    for words in commands {
        let command = words.join(" ");
        let start = rows.len();
        for &device in devices {
            rows.push(CommandRow {
                command: command.clone(),
                device,
                runs_seconds: Vec::new(),
                median_seconds: 0.0,
                peak_rss_bytes: None,
            });
        }
        for run in 1..=runs {
            for (k, &device) in devices.iter().enumerate() {
                eprintln!("bench: `luxeval {command} --device {device}`, run {run} of {runs} …");
                let (seconds, rss) = run_once(&exe, words, device)?;
                let row = &mut rows[start + k];
                row.runs_seconds.push(seconds);
                // None < Some: the largest figure reported.
                row.peak_rss_bytes = row.peak_rss_bytes.max(rss);
            }
        }
        for row in &mut rows[start..] {
            row.median_seconds = crate::bench::median(row.runs_seconds.clone());
        }
    }
    Ok(rows)
}

/// CPU time ÷ GPU time of each command measured on both: how many times faster the GPU path is.
pub fn speedups(rows: &[CommandRow]) -> Vec<(String, f64)> {
    rows.iter()
        .filter(|g| g.device == "gpu")
        .filter_map(|g| {
            let c = rows
                .iter()
                .find(|c| c.device == "cpu" && c.command == g.command)?;
            Some((g.command.clone(), c.median_seconds / g.median_seconds))
        })
        .collect()
}

/// One child: `exe WORDS --device DEVICE`, stdout discarded, stderr kept for the message should
/// it fail. A failing command fails the bench with the child's exit code (2 for bad input) and
/// the end of its message.
fn run_once(exe: &Path, words: &[String], device: &str) -> CliResult<(f64, Option<u64>)> {
    let file_failed = |e: std::io::Error| {
        Failure::runtime(format!("creating a file for the command's messages: {e}"))
    };
    let stderr = tempfile::tempfile().map_err(file_failed)?;
    let keep = stderr.try_clone().map_err(file_failed)?;
    let t = Instant::now();
    let child = Command::new(exe)
        .args(words)
        .args(["--device", device])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::from(stderr))
        .spawn()
        .map_err(|e| Failure::runtime(format!("starting {}: {e}", exe.display())))?;
    let (status, rss) = wait(child)
        .map_err(|e| Failure::runtime(format!("waiting for `luxeval {}`: {e}", words.join(" "))))?;
    let seconds = t.elapsed().as_secs_f64();
    if !status.success() {
        let message = read_tail(keep);
        let code = if status.code() == Some(2) { 2 } else { 1 };
        return Err(Failure {
            code,
            message: format!(
                "--command `luxeval {} --device {device}` failed ({status}): {message}",
                words.join(" ")
            ),
        });
    }
    Ok((seconds, rss))
}

/// The last lines the child wrote to stderr (its error message), at most 2,000 bytes.
fn read_tail(mut f: std::fs::File) -> String {
    use std::io::{Read, Seek, SeekFrom};
    let mut s = String::new();
    let len = f.seek(SeekFrom::End(0)).unwrap_or(0);
    let from = len.saturating_sub(2000);
    if f.seek(SeekFrom::Start(from)).is_ok() {
        let mut bytes = Vec::new();
        let _ = f.read_to_end(&mut bytes);
        s = String::from_utf8_lossy(&bytes).trim().to_string();
    }
    if s.is_empty() { "no message".into() } else { s }
}

/// Waits for `child` and reads its peak resident set from the kernel's accounting (`wait4`'s
/// rusage; Linux reports `ru_maxrss` in KiB), which a parent cannot read from /proc once the
/// child has exited.
#[cfg(unix)]
fn wait(child: std::process::Child) -> std::io::Result<(ExitStatus, Option<u64>)> {
    use std::os::unix::process::ExitStatusExt;
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: rusage is plain data, zeroed is a valid value; wait4 writes it and `status`.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: `pid` is our child, not yet reaped (std's Child reaps only in wait/try_wait,
        // which are not called on it).
        let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
        if r == pid {
            break;
        }
        let e = std::io::Error::last_os_error();
        if e.kind() != std::io::ErrorKind::Interrupted {
            return Err(e);
        }
    }
    let rss = u64::try_from(usage.ru_maxrss).ok().map(|kib| kib * 1024);
    Ok((ExitStatus::from_raw(status), rss))
}

#[cfg(not(unix))]
fn wait(mut child: std::process::Child) -> std::io::Result<(ExitStatus, Option<u64>)> {
    Ok((child.wait()?, None))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_splits_and_refuses_what_the_bench_sets() {
        assert_eq!(
            parse("  falloff s.usda  --res 8,8 -o m.exr ").unwrap(),
            ["falloff", "s.usda", "--res", "8,8", "-o", "m.exr"]
        );
        assert!(parse("   ").is_err());
        assert!(
            parse("falloff s.usda --device cpu")
                .unwrap_err()
                .contains("--device")
        );
        assert!(
            parse("emission s.usda --device=gpu")
                .unwrap_err()
                .contains("--device")
        );
        assert!(parse("bench --samples 8").is_err());
    }

    #[test]
    fn speedup_is_cpu_time_over_gpu_time_of_the_same_command() {
        let row = |command: &str, device, median_seconds| CommandRow {
            command: command.into(),
            device,
            runs_seconds: vec![median_seconds],
            median_seconds,
            peak_rss_bytes: None,
        };
        let rows = [
            row("a", "gpu", 2.0),
            row("a", "cpu", 6.0),
            row("b", "gpu", 1.0),
        ];
        assert_eq!(speedups(&rows), [("a".to_string(), 3.0)]);
    }
}
