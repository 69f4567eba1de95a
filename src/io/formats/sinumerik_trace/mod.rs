//! SINUMERIK / SINAMICS measuring-function files (`format: "sinumerik-trace"`): the
//! XML that the commissioning software's frequency-response measurement saves (SAT
//! library, root element `ResponseTestCustom` or another `ResponseTest…`).
//!
//! # The file
//!
//! As the shared sample holds it (`fixtures/formats/sinumerik/freq_trace.XML`, SAT
//! library 4.7.6.0.3; its README gives the provenance): an ISO-8859-1 XML document
//! (ASCII in practice) whose elements are the library's objects' members, each named
//! by its `name` attribute and typed by its tag ([`document`]). What is read:
//!
//! - the test: `m_dProcessUpdateTime` (the sample time), `m_eControlLoopType`,
//!   `m_eWaveformType`, `m_eInjectionPoint_rtc`, the time stamp and platform;
//! - `m_ExcitationSourceList`: the PRBS order, whether the loop was closed, the axis
//!   (rotary or linear, direct drive, linear motor, motor-to-axis ratio, torque
//!   constant) and per direction the offset and the excitation amplitude;
//! - `m_listpResponseTestConditions`: per direction the settling and measurement
//!   times, the averages set, the sampling interval and the bandwidth;
//! - `m_MeasurementSignalNodeList`: each signal's time series (one period per
//!   direction), its autospectrum and its cross spectra with the others, all as
//!   base85 arrays ([`base85`]) whose declared `m_length` must be what they hold;
//! - `m_listPrimaryFreqRespSigNodeData`: which signals are the primary response's
//!   input and output.
//!
//! What each means and how the response is formed from the spectra: [`response`].
//! What the file does not hold: the speed controller's settings, the machine and its
//! mechanics (a measurement saved alone lacks them).
//!
//! # Channels
//!
//! Named by what they are where the loop is known (`speed setpoint, positive`,
//! `actual speed, negative`, `autospectrum of speed setpoint`, `cross spectrum of
//! actual speed and speed setpoint`, the primary response `actual speed / speed
//! setpoint` at the DFT's lines), by signal number otherwise; the series in rad/s of
//! the motor for the speed loop, with [`Abscissa::Uniform`] time; the spectra with the
//! file's frequency vector. The notes say the loop, the excitation, the offsets,
//! the axis and the frequencies' discrepancy ([`response`]).
//!
//! # Robustness
//!
//! The file is read whole (at most [`MAX_BYTES`]; the shared one is 199 kB) and
//! parsed by roxmltree, whose errors give a line and column, turned into the byte;
//! every other error names the element (tag and `name`) and the byte it starts at, a
//! base85 fault the byte of the character.

mod base85;
mod channels;
mod document;
pub mod measurement;
pub mod response;

#[cfg(test)]
mod tests;

use std::io::Read;
use std::path::Path;

use super::{FormatError, Location, Recording};
pub use measurement::Measurement;

/// The largest file read: measuring-function files hold a few hundred kilobytes.
pub const MAX_BYTES: u64 = 32 << 20;

/// At most this many XML nodes (the shared file has about 3 000).
const MAX_NODES: u32 = 1_000_000;

/// The format as `--format` names it and [`super::detect`] recognises it.
pub static DEFINITION: super::format::Definition = super::format::Definition {
    name: "sinumerik-trace",
    sniff: |head| sniff(head.bytes),
    read,
};

/// Whether a file's first bytes are an XML document of the SAT library: an XML
/// declaration and an element with a `satclassid` attribute.
pub fn sniff(head: &[u8]) -> bool {
    let head = head.strip_prefix("\u{feff}".as_bytes()).unwrap_or(head);
    let text = String::from_utf8_lossy(head);
    text.trim_start().starts_with("<?xml") && text.contains("satclassid=")
}

/// Reads a measuring-function file as channels.
pub fn read(path: &Path) -> Result<Recording, FormatError> {
    Ok(channels::recording(&read_measurement(path)?))
}

/// Reads a measuring-function file, typed.
pub fn read_measurement(path: &Path) -> Result<Measurement, FormatError> {
    let text = document::Text::decode(read_bytes(path)?);
    let options = roxmltree::ParsingOptions {
        nodes_limit: MAX_NODES,
        ..Default::default()
    };
    let xml = roxmltree::Document::parse_with_options(&text.text, options).map_err(|e| {
        let pos = e.pos();
        let at = text.offset_of(pos.row, pos.col);
        FormatError::new(
            path,
            Location::Byte(text.byte(at)),
            format!("not well-formed XML: {e}"),
        )
    })?;
    let root = xml.root_element();
    let doc = document::Doc { path, text: &text };
    if !root.tag_name().name().starts_with("ResponseTest") {
        return Err(doc.fail(
            root,
            "a SAT library file, but not a measuring function's (root `ResponseTest…`): \
             rtid reads the frequency-response measurements",
        ));
    }
    Measurement::of(&doc, root)
}

/// The file's bytes, refused beyond [`MAX_BYTES`].
fn read_bytes(path: &Path) -> Result<Vec<u8>, FormatError> {
    let fail = |m: String| FormatError::new(path, Location::File, m);
    let file = crate::io::open_input(path).map_err(|e| fail(format!("cannot open: {e}")))?;
    let len = file
        .metadata()
        .map_err(|e| fail(format!("cannot read its size: {e}")))?
        .len();
    if len > MAX_BYTES {
        return Err(fail(format!(
            "{len} bytes: a measuring-function file holds a few hundred kB; rtid reads \
             at most {MAX_BYTES}"
        )));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(MAX_BYTES)
        .read_to_end(&mut bytes)
        .map_err(|e| fail(format!("cannot read: {e}")))?;
    Ok(bytes)
}
