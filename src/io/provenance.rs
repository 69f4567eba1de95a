//! Where a result came from: the command line that wrote it, the rtid that ran it
//! and the SHA-256 of each input file as it was read, so a report can show that its
//! figures belong to these files.

use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// The command, the version and the inputs of a result.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The command line, quoted for a POSIX shell.
    pub command: String,
    /// `rtid --version` of the program that wrote the result.
    pub version: String,
    /// Each input file (manifests, their data, a parameter file) as it was read.
    pub inputs: Vec<InputFile>,
}

/// One input file and its SHA-256.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InputFile {
    /// The path as given on the command line (or as a manifest names its data).
    pub path: String,
    /// Hex SHA-256 of its bytes.
    pub sha256: String,
}

impl Provenance {
    /// This process's command line (the program by its name, not the folder it was
    /// run from) and version, with `inputs` hashed now.
    pub fn of_this_run(inputs: &[&Path]) -> std::io::Result<Provenance> {
        let mut args: Vec<String> = std::env::args().collect();
        if let Some(name) = args.first().and_then(|a| Path::new(a).file_name()) {
            args[0] = name.to_string_lossy().into_owned();
        }
        Ok(Provenance {
            command: quoted(&args),
            version: crate::version::VERSION.to_string(),
            inputs: inputs
                .iter()
                .map(|p| {
                    Ok(InputFile {
                        path: p.display().to_string(),
                        sha256: sha256(p)?,
                    })
                })
                .collect::<std::io::Result<_>>()?,
        })
    }
}

/// The words joined into one line a POSIX shell splits back into them.
pub fn quoted(words: &[String]) -> String {
    words
        .iter()
        .map(|w| shlex::try_quote(w).map_or_else(|_| w.clone(), |q| q.into_owned()))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The hex SHA-256 of the input file `path` (a regular file, [`super::open_input`]).
pub fn sha256(path: &Path) -> std::io::Result<String> {
    let mut hasher = Sha256::new();
    std::io::copy(&mut super::open_input(path)?, &mut hasher)?;
    Ok(format!("{:x}", hasher.finalize()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quoted_command_splits_back_into_its_words() {
        let words: Vec<String> = [
            "rtid",
            "identify",
            "my data.json",
            "--set",
            "Kw=4e5",
            "it's",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let line = quoted(&words);
        assert_eq!(shlex::split(&line).unwrap(), words, "{line}");
        assert!(
            line.starts_with("rtid identify 'my data.json' --set "),
            "{line}"
        );
    }

    #[test]
    fn the_hash_is_sha256_of_the_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("abc.txt");
        std::fs::write(&file, "abc").unwrap();
        assert_eq!(
            sha256(&file).unwrap(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
