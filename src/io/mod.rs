//! Files in and out: parameter files, experiment files, atomic writes, provenance;
//! [`formats`]: the formats labs export.

pub mod atomic;
pub mod compensation_file;
pub mod drive_settings;
pub mod experiment_file;
pub mod formats;
pub mod import;
pub mod json;
pub mod params_file;
pub mod provenance;
pub mod torque_file;

/// JSON text without a leading UTF-8 byte-order mark (editors on Windows write one;
/// JSON parsers refuse it at "line 1, column 1").
pub fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// The largest file rtid reads as an input (4 GiB): beyond it a path is a mistake
/// (a disk image, a device), not a record.
pub const MAX_INPUT_BYTES: u64 = 4 << 30;

/// Opens an input file: a regular file (not a device such as /dev/zero, a folder or a
/// pipe, which would be read for ever) of at most [`MAX_INPUT_BYTES`].
pub fn open_input(path: &std::path::Path) -> std::io::Result<std::fs::File> {
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, a folder or a pipe)",
        ));
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{} bytes, over the 4 GiB an input may have", meta.len()),
        ));
    }
    Ok(file)
}

/// The text of an input file ([`open_input`]).
pub fn read_input(path: &std::path::Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut text = String::new();
    open_input(path)?.read_to_string(&mut text)?;
    Ok(text)
}
