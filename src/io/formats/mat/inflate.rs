//! `miCOMPRESSED` elements: a zlib stream (RFC 1950) holding one whole data element,
//! inflated in steps into a buffer that never grows past a limit, so that a small
//! file declaring (or really holding) gigabytes of zeros cannot exhaust memory.

use flate2::{Decompress, FlushDecompress, Status};

use super::fault::Problem;

/// The first step's output room (the buffer then doubles, up to the limit).
const FIRST_STEP: usize = 64 * 1024;

/// The zlib stream `compressed` inflated, if it is whole, valid (the Adler-32 checksum
/// included) and inflates to at most `limit` bytes.
pub(super) fn inflate(compressed: &[u8], limit: u64) -> Result<Vec<u8>, Problem> {
    let limit = usize::try_from(limit).unwrap_or(usize::MAX);
    let mut stream = Decompress::new(true);
    let mut out: Vec<u8> = Vec::new();
    loop {
        if out.len() == out.capacity() {
            let room = limit.saturating_sub(out.len());
            if room == 0 {
                return finish_at_limit(&mut stream, compressed, out, limit);
            }
            out.reserve_exact(out.len().max(FIRST_STEP).min(room));
        }
        let (read, written) = (stream.total_in(), out.len());
        let input = &compressed[consumed(&stream, compressed.len())..];
        let status = stream
            .decompress_vec(input, &mut out, FlushDecompress::None)
            .map_err(|e| Problem::Inflate(e.to_string()))?;
        if out.len() > limit {
            // Only if the allocator gave more room than asked for.
            return Err(Problem::InflatedTooLarge {
                limit: limit as u64,
            });
        }
        if status == Status::StreamEnd {
            return Ok(out);
        }
        let progressed = stream.total_in() != read || out.len() != written;
        if !progressed && out.len() < out.capacity() {
            return Err(Problem::Inflate(format!(
                "its zlib stream stops after {} of its {} bytes",
                stream.total_in(),
                compressed.len()
            )));
        }
    }
}

/// How many input bytes the stream has consumed, as an index into the input.
fn consumed(stream: &Decompress, len: usize) -> usize {
    usize::try_from(stream.total_in()).map_or(len, |n| n.min(len))
}

/// At the limit: whole if only the stream's checksum was left to read, too large if
/// any more data would follow.
fn finish_at_limit(
    stream: &mut Decompress,
    compressed: &[u8],
    mut out: Vec<u8>,
    limit: usize,
) -> Result<Vec<u8>, Problem> {
    let input = &compressed[consumed(stream, compressed.len())..];
    match stream.decompress_vec(input, &mut out, FlushDecompress::None) {
        Ok(Status::StreamEnd) => Ok(out),
        _ => Err(Problem::InflatedTooLarge {
            limit: limit as u64,
        }),
    }
}
