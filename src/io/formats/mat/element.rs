//! Data elements, the MAT-file's unit of storage (MathWorks, "MAT-File Format",
//! Version 7, ch. 1, "Data Element Format"): an 8-byte tag (a 32-bit data type and a
//! 32-bit byte count, in the file's byte order) and the data, padded to 8 bytes; or
//! the "small data element format", where a tag's upper 16 bits hold a byte count of
//! at most 4 and the data fill the tag's second word. `miCOMPRESSED` elements are not
//! padded.
//!
//! A [`Cursor`] walks the elements of one region (the file after its header, an
//! inflated `miCOMPRESSED` element, the body of an `miMATRIX`) and refuses an element
//! that runs past the region's end before anything is read from it.

use super::fault::{Fault, Origin, Problem};

/// The byte order the header's indicator declares ('IM': little-endian, 'MI': big).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum ByteOrder {
    Little,
    Big,
}

impl ByteOrder {
    pub(super) fn u16(self, b: [u8; 2]) -> u16 {
        match self {
            ByteOrder::Little => u16::from_le_bytes(b),
            ByteOrder::Big => u16::from_be_bytes(b),
        }
    }

    pub(super) fn u32(self, b: [u8; 4]) -> u32 {
        match self {
            ByteOrder::Little => u32::from_le_bytes(b),
            ByteOrder::Big => u32::from_be_bytes(b),
        }
    }
}

/// The data types of the format's Table 1-1 (codes 8, 10 and 11 are reserved).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum DataType {
    Int8,
    UInt8,
    Int16,
    UInt16,
    Int32,
    UInt32,
    Single,
    Double,
    Int64,
    UInt64,
    Matrix,
    Compressed,
    Utf8,
    Utf16,
    Utf32,
}

impl DataType {
    fn from_code(code: u32) -> Option<DataType> {
        Some(match code {
            1 => DataType::Int8,
            2 => DataType::UInt8,
            3 => DataType::Int16,
            4 => DataType::UInt16,
            5 => DataType::Int32,
            6 => DataType::UInt32,
            7 => DataType::Single,
            9 => DataType::Double,
            12 => DataType::Int64,
            13 => DataType::UInt64,
            14 => DataType::Matrix,
            15 => DataType::Compressed,
            16 => DataType::Utf8,
            17 => DataType::Utf16,
            18 => DataType::Utf32,
            _ => return None,
        })
    }

    /// The name the format's documentation gives it.
    pub(super) fn name(self) -> &'static str {
        match self {
            DataType::Int8 => "miINT8",
            DataType::UInt8 => "miUINT8",
            DataType::Int16 => "miINT16",
            DataType::UInt16 => "miUINT16",
            DataType::Int32 => "miINT32",
            DataType::UInt32 => "miUINT32",
            DataType::Single => "miSINGLE",
            DataType::Double => "miDOUBLE",
            DataType::Int64 => "miINT64",
            DataType::UInt64 => "miUINT64",
            DataType::Matrix => "miMATRIX",
            DataType::Compressed => "miCOMPRESSED",
            DataType::Utf8 => "miUTF8",
            DataType::Utf16 => "miUTF16",
            DataType::Utf32 => "miUTF32",
        }
    }

    /// The size of one value of a numeric type; `None` for the others.
    pub(super) fn numeric_size(self) -> Option<usize> {
        match self {
            DataType::Int8 | DataType::UInt8 => Some(1),
            DataType::Int16 | DataType::UInt16 => Some(2),
            DataType::Int32 | DataType::UInt32 | DataType::Single => Some(4),
            DataType::Double | DataType::Int64 | DataType::UInt64 => Some(8),
            _ => None,
        }
    }
}

/// A region of a buffer holding data elements one after another.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cursor<'a> {
    /// The whole buffer (the file, or one inflated element): offsets are into it.
    bytes: &'a [u8],
    pos: usize,
    end: usize,
    /// What `end` is, for messages ("the end of the file").
    end_name: &'static str,
    order: ByteOrder,
    origin: Origin,
}

/// One data element: its type, where its tag is, and its data.
#[derive(Clone, Copy, Debug)]
pub(super) struct Element<'a> {
    pub data_type: DataType,
    /// The offset of its tag in the cursor's buffer.
    pub at: usize,
    /// Its data, as a region (an `miMATRIX`'s sub-elements are read from it).
    pub body: Cursor<'a>,
}

impl<'a> Cursor<'a> {
    /// The region `bytes[start..]`, whose end is called `end_name` in messages.
    pub(super) fn new(
        bytes: &'a [u8],
        start: usize,
        order: ByteOrder,
        origin: Origin,
        end_name: &'static str,
    ) -> Cursor<'a> {
        Cursor {
            bytes,
            pos: start.min(bytes.len()),
            end: bytes.len(),
            end_name,
            order,
            origin,
        }
    }

    pub(super) fn order(&self) -> ByteOrder {
        self.order
    }

    pub(super) fn position(&self) -> usize {
        self.pos
    }

    /// The bytes from the position to the region's end.
    pub(super) fn rest(&self) -> &'a [u8] {
        &self.bytes[self.pos..self.end]
    }

    pub(super) fn is_at_end(&self) -> bool {
        self.pos >= self.end
    }

    /// A fault at offset `at` of this cursor's buffer.
    pub(super) fn fault(&self, at: usize, problem: Problem) -> Fault {
        Fault {
            origin: self.origin,
            at,
            problem,
        }
    }

    /// Reads the next element's tag, checks that its data lie inside the region, and
    /// moves past it (and its padding).
    pub(super) fn next_element(&mut self) -> Result<Element<'a>, Fault> {
        let at = self.pos;
        let left = self.end - at;
        if left < 8 {
            return Err(self.fault(
                at,
                Problem::TagCut {
                    left,
                    end: self.end_name,
                },
            ));
        }
        let word = self.u32_at(at);
        let small = word >> 16 != 0;
        let (code, len, start) = if small {
            let len = word >> 16;
            if len > 4 {
                return Err(self.fault(at, Problem::SmallTooLong(len)));
            }
            (word & 0xFFFF, len as usize, at + 4)
        } else {
            let len = self.u32_at(at + 4) as usize;
            let start = at + 8;
            if len > self.end - start {
                return Err(self.fault(
                    at,
                    Problem::RunsPast {
                        declared: len as u64,
                        left: self.end - start,
                        end: self.end_name,
                    },
                ));
            }
            (word, len, start)
        };
        let data_type =
            DataType::from_code(code).ok_or_else(|| self.fault(at, Problem::UnknownType(code)))?;
        let next = if small {
            at + 8
        } else if data_type == DataType::Compressed {
            start + len
        } else {
            len.checked_next_multiple_of(8)
                .map_or(self.end, |padded| start.saturating_add(padded))
        };
        // A last element may lack its padding: the file simply ends.
        self.pos = next.min(self.end);
        let body = Cursor {
            pos: start,
            end: start + len,
            end_name: "the end of the element holding it",
            ..*self
        };
        Ok(Element {
            data_type,
            at,
            body,
        })
    }

    fn u32_at(&self, at: usize) -> u32 {
        self.order.u32(array(&self.bytes[at..at + 4]))
    }
}

impl<'a> Element<'a> {
    pub(super) fn data(&self) -> &'a [u8] {
        self.body.rest()
    }

    /// Refuses the element unless its type is one of `allowed`; `what` names it.
    pub(super) fn expect(
        &self,
        what: &'static str,
        allowed: &[DataType],
        expected: &'static str,
    ) -> Result<(), Fault> {
        if allowed.contains(&self.data_type) {
            Ok(())
        } else {
            Err(self.body.fault(
                self.at,
                Problem::UnexpectedType {
                    what,
                    found: self.data_type.name(),
                    expected,
                },
            ))
        }
    }

    /// How many numeric values the element holds, refusing a non-numeric type or a
    /// byte count that is not a whole number of values.
    pub(super) fn value_count(&self, what: &'static str) -> Result<u64, Fault> {
        let size = self.data_type.numeric_size().ok_or_else(|| {
            self.body.fault(
                self.at,
                Problem::UnexpectedType {
                    what,
                    found: self.data_type.name(),
                    expected: "numbers",
                },
            )
        })?;
        let len = self.data().len();
        if len % size != 0 {
            return Err(self
                .body
                .fault(self.at, Problem::Ragged { what, len, size }));
        }
        Ok((len / size) as u64)
    }

    /// The first 32-bit word of the data (array flags, a field-name length).
    pub(super) fn first_u32(&self, what: &'static str) -> Result<u32, Fault> {
        let data = self.data();
        if data.len() < 4 {
            return Err(self.body.fault(
                self.at,
                Problem::Ragged {
                    what,
                    len: data.len(),
                    size: 4,
                },
            ));
        }
        Ok(self.body.order.u32(array(&data[..4])))
    }
}

/// Values decoded to `f64`, and whether some 64-bit integer was rounded on the way
/// (beyond ±2^53 not every integer is a double).
pub(super) struct Decoded {
    pub values: Vec<f64>,
    pub rounded: bool,
}

/// `data` as values of type `$t` in the byte order `$little` says, each mapped by
/// `$f`.
macro_rules! values {
    ($data:expr, $little:expr, $t:ty, $f:expr) => {
        convert($data, |b| {
            $f(if $little {
                <$t>::from_le_bytes(b)
            } else {
                <$t>::from_be_bytes(b)
            })
        })
    };
}

/// The numeric values of `data`, stored as `data_type` in byte order `order`.
/// `data_type` must be numeric and `data` a whole number of its values
/// ([`Element::value_count`] checks both).
pub(super) fn decode(data: &[u8], data_type: DataType, order: ByteOrder) -> Decoded {
    let little = order == ByteOrder::Little;
    let plain = |values| Decoded {
        values,
        rounded: false,
    };
    match data_type {
        DataType::Int8 => plain(values!(data, little, i8, f64::from)),
        DataType::UInt8 => plain(values!(data, little, u8, f64::from)),
        DataType::Int16 => plain(values!(data, little, i16, f64::from)),
        DataType::UInt16 => plain(values!(data, little, u16, f64::from)),
        DataType::Int32 => plain(values!(data, little, i32, f64::from)),
        DataType::UInt32 => plain(values!(data, little, u32, f64::from)),
        DataType::Single => plain(values!(data, little, f32, f64::from)),
        DataType::Double => plain(values!(data, little, f64, |v| v)),
        DataType::Int64 => {
            let ints = values!(data, little, i64, |v| v);
            Decoded {
                rounded: ints.iter().any(|v| v.unsigned_abs() > EXACT_INTEGERS),
                values: ints.into_iter().map(|v| v as f64).collect(),
            }
        }
        DataType::UInt64 => {
            let ints = values!(data, little, u64, |v| v);
            Decoded {
                rounded: ints.iter().any(|&v| v > EXACT_INTEGERS),
                values: ints.into_iter().map(|v| v as f64).collect(),
            }
        }
        _ => plain(Vec::new()),
    }
}

/// Largest magnitude up to which every integer is exactly a double.
const EXACT_INTEGERS: u64 = 1 << 53;

fn convert<const N: usize, T>(data: &[u8], f: impl Fn([u8; N]) -> T) -> Vec<T> {
    data.chunks_exact(N).map(|c| f(array(c))).collect()
}

/// The first `N` bytes of `bytes` as an array; callers pass exactly `N` bytes.
pub(super) fn array<const N: usize>(bytes: &[u8]) -> [u8; N] {
    let mut out = [0u8; N];
    out.copy_from_slice(&bytes[..N]);
    out
}
