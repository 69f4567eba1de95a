//! The 128-byte header (MathWorks, "MAT-File Format", Version 7, "MAT-File Header
//! Format"): 116 bytes of text, 8 bytes of subsystem-data offset, a 16-bit version
//! (0x0100) and the endian indicator 'IM' written as a 16-bit number, so that a
//! reader sees 'IM' in a little-endian file and 'MI' in a big-endian one.
//!
//! A MATLAB 7.3 file (`save -v7.3`) is an HDF5 file behind the same header: its text
//! starts "MATLAB 7.3 MAT-file", its version is 0x0200 and the HDF5 signature follows
//! at byte 512. It is refused with the way to save a version 7 file instead.

use super::element::{array, ByteOrder};
use super::fault::{Fault, Origin, Problem};

/// The header's length; the first data element follows it.
pub(super) const HEADER_LEN: usize = 128;

const VERSION_5: u16 = 0x0100;
const VERSION_73: u16 = 0x0200;
const TEXT_73: &[u8] = b"MATLAB 7.3";
/// The HDF5 superblock signature, at byte 512 of a 7.3 MAT-file (HDF5 specification,
/// "Format Signature").
const HDF5_SIGNATURE: &[u8] = b"\x89HDF\r\n\x1a\n";
const HDF5_AT: usize = 512;

/// The byte order of a level 5 MAT-file, or why `bytes` is not one.
pub(super) fn byte_order(bytes: &[u8]) -> Result<ByteOrder, Fault> {
    let fault = |at, problem| Fault {
        origin: Origin::File,
        at,
        problem,
    };
    if bytes.is_empty() {
        return Err(fault(0, Problem::Empty));
    }
    if is_version_73(bytes) {
        return Err(fault(0, Problem::Version73));
    }
    if bytes.len() < HEADER_LEN {
        return Err(fault(bytes.len(), Problem::ShortHeader));
    }
    let order = match &bytes[126..128] {
        b"IM" => ByteOrder::Little,
        b"MI" => ByteOrder::Big,
        other => {
            let found = format!("0x{:02x} 0x{:02x}", other[0], other[1]);
            return Err(fault(126, Problem::NoByteOrder(found)));
        }
    };
    match order.u16(array(&bytes[124..126])) {
        VERSION_5 => Ok(order),
        VERSION_73 => Err(fault(124, Problem::Version73)),
        other => Err(fault(124, Problem::UnknownVersion(other))),
    }
}

fn is_version_73(bytes: &[u8]) -> bool {
    bytes.starts_with(TEXT_73)
        || bytes
            .get(HDF5_AT..HDF5_AT + HDF5_SIGNATURE.len())
            .is_some_and(|s| s == HDF5_SIGNATURE)
}
