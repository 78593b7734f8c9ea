//! What the command line's tests share: the repository's files by name, the `luxeval` binary,
//! and reading back what it wrote.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `rel` (a path in the repository) as a string argument.
pub fn repo_file(rel: &str) -> String {
    crate::repo().join(rel).to_string_lossy().into_owned()
}

/// A file of assets/.
pub fn asset(name: &str) -> String {
    repo_file(&format!("assets/{name}"))
}

/// A luxtest stage (tests/data/luxtest/usd/).
pub fn luxtest(name: &str) -> String {
    repo_file(&format!("tests/data/luxtest/usd/{name}"))
}

/// A file of tests/data/textures/.
pub fn texture_data(name: &str) -> String {
    repo_file(&format!("tests/data/textures/{name}"))
}

/// A file of the bad-input corpus (tests/data/bad/).
pub fn bad(name: &str) -> String {
    repo_file(&format!("tests/data/bad/{name}"))
}

/// The `luxeval` binary this test run built, as a command to add arguments to.
pub fn command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_luxeval"))
}

/// Runs `luxeval ARGS` to completion.
pub fn luxeval(args: &[&str]) -> Output {
    command().args(args).output().expect("run luxeval")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The shape and values of a float32 `.npy` file's bytes.
pub fn f32_values(bytes: &[u8]) -> (Vec<u64>, Vec<f32>) {
    let f = npyz::NpyFile::new(bytes).unwrap();
    let shape = f.shape().to_vec();
    (shape, f.into_vec::<f32>().unwrap())
}

/// The shape and values of a float32 `.npy` file.
pub fn read_npy_f32(path: &Path) -> (Vec<u64>, Vec<f32>) {
    f32_values(&std::fs::read(path).unwrap())
}

/// Every entry of `dir`, sorted (a failed command must leave none behind).
pub fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}
