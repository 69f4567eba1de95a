//! Atomic file output: write a temporary file beside the target, then rename it over
//! the target, so a reader never sees a half-written file and an interrupted run
//! leaves the previous version intact. The file gets the permissions the user's umask
//! gives a new file (0644 under the usual 022), not a temporary file's private 0600:
//! sweep shards on a cluster are read by colleagues.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporary files being written now, for [`remove_unfinished`].
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Deletes every temporary file still being written: called when the process is
/// interrupted (Ctrl-C, SIGTERM) and exits at once, so that no half-written `.tmp`
/// file is left behind (a killed long simulation left 800 MB).
pub fn remove_unfinished() {
    if let Ok(live) = LIVE.lock() {
        for path in live.iter() {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// A temporary file's entry in [`LIVE`] while it is being written.
struct Live(PathBuf);

impl Live {
    fn of(tmp: &tempfile::NamedTempFile) -> Live {
        let path = tmp.path().to_path_buf();
        if let Ok(mut live) = LIVE.lock() {
            live.push(path.clone());
        }
        Live(path)
    }
}

impl Drop for Live {
    fn drop(&mut self) {
        if let Ok(mut live) = LIVE.lock() {
            live.retain(|p| p != &self.0);
        }
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = temporary_in(dir)?;
    let _live = Live::of(&tmp);
    tmp.as_file().write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path)
        .map_err(|e| without_temporary_name(e.error))?;
    Ok(())
}

/// Streams into a temporary file beside `path` through `fill`, then renames it over
/// `path`. If `fill` fails, `path` is left untouched and the temporary file removed.
pub fn write_with<E: From<std::io::Error>>(
    path: &Path,
    fill: impl FnOnce(&mut std::io::BufWriter<&std::fs::File>) -> Result<(), E>,
) -> Result<(), E> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = temporary_in(dir)?;
    let _live = Live::of(&tmp);
    {
        let mut w = std::io::BufWriter::new(tmp.as_file());
        fill(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path)
        .map_err(|e| without_temporary_name(e.error))?;
    Ok(())
}

/// A temporary file in `dir` created with mode 0666, which the system masks with the
/// umask as for any new file.
fn temporary_in(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir).map_err(without_temporary_name)
}

/// The error `e` without the temporary file's name that `tempfile` appends ("… at
/// path \"dir/.tmpXYZ\""): the user asked for the target, and the temporary name
/// means nothing to them. (`tempfile` keeps the cause private, so the text is cut.)
fn without_temporary_name(e: std::io::Error) -> std::io::Error {
    let text = e.to_string();
    match text.rsplit_once(" at path \"") {
        Some((cause, _)) => std::io::Error::new(e.kind(), cause.to_string()),
        None => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_error_does_not_name_the_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing").join("out.json");
        let e = write(&path, b"{}").unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
        assert!(!e.to_string().contains(".tmp"), "{e}");
    }

    #[test]
    fn a_failed_fill_leaves_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        write(&path, b"old").unwrap();
        let r: Result<(), std::io::Error> = write_with(&path, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("interrupted"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// The written file's mode is a new file's under the process's umask, compared
    /// with a file made by `File::create` in the same folder.
    #[cfg(unix)]
    #[test]
    fn the_file_gets_the_umask_permissions_of_a_new_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain");
        std::fs::File::create(&plain).unwrap();
        let path = dir.path().join("out.json");
        write(&path, b"{}").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(
            mode(&path),
            mode(&plain),
            "a new file's mode, not a temporary's 0600"
        );
    }
}
