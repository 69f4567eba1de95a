//! `miMATRIX` elements, one MATLAB array each (MathWorks, "MAT-File Format",
//! Version 7, "miMATRIX Format", Tables 1-2 to 1-6): array flags (class, complex,
//! logical), dimensions, name, then by class the real and imaginary parts of a
//! numeric array, or a struct's field names and one `miMATRIX` per element and field.
//!
//! Numeric arrays of every class become channels (a vector or scalar one channel, a
//! matrix one per column named `name(:,j)`); structs become their fields' channels
//! named `rec.field` (`s(k).field` for element k of a struct array); the rest (char
//! arrays, cells, sparse matrices, objects, empty arrays) is skipped with a note.

use super::element::{decode, Cursor, DataType, Element};
use super::fault::{Fault, Problem};
use super::found::Found;

/// How deep structs may nest: far beyond real records, and a bound on the recursion a
/// crafted file can cause.
pub(super) const MAX_DEPTH: usize = 32;

/// The array classes of Table 1-3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    Cell,
    Struct,
    Object,
    Char,
    Sparse,
    /// mxDOUBLE to mxUINT64 (codes 6 to 15).
    Numeric,
    FunctionHandle,
    /// MATLAB classes (string, table, datetime…) whose data live in the subsystem.
    Opaque,
}

impl Class {
    fn from_code(code: u32) -> Option<Class> {
        Some(match code {
            1 => Class::Cell,
            2 => Class::Struct,
            3 => Class::Object,
            4 => Class::Char,
            5 => Class::Sparse,
            6..=15 => Class::Numeric,
            16 => Class::FunctionHandle,
            17 => Class::Opaque,
            _ => return None,
        })
    }

    /// What a skipped array of this class is, for the note.
    fn description(self) -> &'static str {
        match self {
            Class::Cell => "a cell array",
            Class::Struct => "a struct",
            Class::Object => "an object",
            Class::Char => "a char array",
            Class::Sparse => "a sparse matrix",
            Class::Numeric => "a numeric array",
            Class::FunctionHandle => "a function handle",
            Class::Opaque => "a MATLAB object (string, table, datetime…)",
        }
    }
}

/// The array flags sub-element (Table 1-5): class in the low byte, then the complex
/// bit (0x0800). The logical bit (0x0200) needs nothing: a logical array holds its
/// 0 and 1 as miUINT8 numbers.
#[derive(Clone, Copy, Debug)]
struct Flags {
    class: Class,
    complex: bool,
}

const COMPLEX_BIT: u32 = 0x0800;

/// Reads one top-level variable (the body of an `miMATRIX` element), adding its
/// channels or notes to `found`.
pub(super) fn read_variable(element: &Element, found: &mut Found) -> Result<(), Fault> {
    read_array(element, None, 0, found)
}

/// Reads one array: a variable (`path` None: its own name is used) or a struct
/// field (`path` the field's full name, the array's own name being empty).
fn read_array(
    element: &Element,
    path: Option<&str>,
    depth: usize,
    found: &mut Found,
) -> Result<(), Fault> {
    let mut body = element.body;
    if body.is_at_end() {
        // MATLAB writes an empty field ([]) as an miMATRIX with no data.
        found.skip(path.unwrap_or(""), "an empty array");
        return Ok(());
    }
    let flags = read_flags(&mut body)?;
    if flags.class == Class::Opaque {
        // Opaque arrays have no dimensions: the name follows the flags.
        let name = read_name(&mut body)?;
        found.skip(path.unwrap_or(&name), flags.class.description());
        return Ok(());
    }
    let dims = read_dimensions(&mut body)?;
    let own_name = read_name(&mut body)?;
    let name = path.unwrap_or(&own_name);
    if name.is_empty() {
        found.note(format!(
            "an array with no name at byte {} (MATLAB's subsystem data): skipped",
            element.at
        ));
        return Ok(());
    }
    match flags.class {
        Class::Numeric => read_numeric(&mut body, name, &dims, flags, found),
        Class::Struct => read_struct(&mut body, name, &dims, depth, found),
        other => {
            found.skip(name, other.description());
            Ok(())
        }
    }
}

fn read_flags(body: &mut Cursor) -> Result<Flags, Fault> {
    let element = body.next_element()?;
    element.expect("array flags", &[DataType::UInt32], "miUINT32")?;
    let word = element.first_u32("array flags")?;
    let class = Class::from_code(word & 0xFF)
        .ok_or_else(|| body.fault(element.at, Problem::UnknownClass(word & 0xFF)))?;
    Ok(Flags {
        class,
        complex: word & COMPLEX_BIT != 0,
    })
}

/// The dimensions (at least one; MATLAB writes at least two), each checked to be
/// non-negative.
fn read_dimensions(body: &mut Cursor) -> Result<Dimensions, Fault> {
    let element = body.next_element()?;
    element.expect("dimensions", &[DataType::Int32], "miINT32")?;
    element.value_count("dimensions")?;
    let values = decode(element.data(), DataType::Int32, body.order()).values;
    if values.is_empty() {
        return Err(body.fault(element.at, Problem::NoDimensions));
    }
    let dims = Dimensions {
        sizes: values.iter().map(|&v| v as i64).collect(),
        at: element.at,
    };
    if dims.sizes.iter().any(|&d| d < 0) {
        let dims = dims.text();
        return Err(body.fault(element.at, Problem::NegativeDimension { dims }));
    }
    Ok(dims)
}

/// An array's dimensions and where they are declared (for messages).
struct Dimensions {
    sizes: Vec<i64>,
    at: usize,
}

impl Dimensions {
    /// `48×1`, as MATLAB shows sizes.
    fn text(&self) -> String {
        let sizes: Vec<String> = self.sizes.iter().map(i64::to_string).collect();
        sizes.join("×")
    }

    /// The number of values they declare, refusing one beyond 2^64.
    fn count(&self, body: &Cursor) -> Result<u64, Fault> {
        self.sizes
            .iter()
            .try_fold(1u64, |n, &d| n.checked_mul(d as u64))
            .ok_or_else(|| {
                let dims = self.text();
                body.fault(self.at, Problem::DimensionsOverflow { dims })
            })
    }
}

fn read_name(body: &mut Cursor) -> Result<String, Fault> {
    let element = body.next_element()?;
    element.expect(
        "array name",
        &[DataType::Int8, DataType::UInt8, DataType::Utf8],
        "miINT8",
    )?;
    Ok(text(element.data()))
}

/// ASCII (or UTF-8) text up to the first NUL.
fn text(bytes: &[u8]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

fn read_numeric(
    body: &mut Cursor,
    name: &str,
    dims: &Dimensions,
    flags: Flags,
    found: &mut Found,
) -> Result<(), Fault> {
    let count = dims.count(body)?;
    if count == 0 {
        found.skip(name, &format!("an empty {} array", dims.text()));
        return Ok(());
    }
    let re = read_part(body, dims, count, "real part")?;
    let im = if flags.complex {
        Some(read_part(body, dims, count, "imaginary part")?)
    } else {
        None
    };
    if re.1 || im.as_ref().is_some_and(|p| p.1) {
        found.note(format!(
            "`{name}`: 64-bit integers beyond ±2^53 rounded to the nearest double"
        ));
    }
    found.add_array(name, &dims.sizes, re.0, im.map(|p| p.0));
    Ok(())
}

/// One part's values, after checking that the element holds exactly `count` of them
/// (before anything is allocated); and whether some were rounded.
fn read_part(
    body: &mut Cursor,
    dims: &Dimensions,
    count: u64,
    what: &'static str,
) -> Result<(Vec<f64>, bool), Fault> {
    let element = body.next_element()?;
    let held = element.value_count(what)?;
    if held != count {
        let problem = Problem::CountMismatch {
            dims: dims.text(),
            declared: count,
            what,
            held,
        };
        return Err(body.fault(element.at, problem));
    }
    let decoded = decode(element.data(), element.data_type, body.order());
    Ok((decoded.values, decoded.rounded))
}

/// A struct (Table 1-6): the length of each field name, the names, then one
/// `miMATRIX` per element and field, the fields of element 1 first.
fn read_struct(
    body: &mut Cursor,
    name: &str,
    dims: &Dimensions,
    depth: usize,
    found: &mut Found,
) -> Result<(), Fault> {
    if depth >= MAX_DEPTH {
        return Err(body.fault(body.position(), Problem::TooDeep(MAX_DEPTH)));
    }
    let fields = read_field_names(body)?;
    let elements = dims.count(body)?;
    if fields.is_empty() || elements == 0 {
        found.skip(name, "a struct with no fields or no elements");
        return Ok(());
    }
    check_struct_fits(body, elements, fields.len())?;
    for k in 0..elements {
        let prefix = if elements == 1 {
            name.to_string()
        } else {
            format!("{name}({})", k + 1)
        };
        for field in &fields {
            let element = body.next_element()?;
            element.expect("struct field", &[DataType::Matrix], "miMATRIX")?;
            read_array(
                &element,
                Some(&format!("{prefix}.{field}")),
                depth + 1,
                found,
            )?;
        }
    }
    Ok(())
}

fn read_field_names(body: &mut Cursor) -> Result<Vec<String>, Fault> {
    let length = body.next_element()?;
    length.expect("field name length", &[DataType::Int32], "miINT32")?;
    let each = length.first_u32("field name length")?;
    let names = body.next_element()?;
    names.expect("field names", &[DataType::Int8, DataType::UInt8], "miINT8")?;
    let data = names.data();
    if data.is_empty() {
        return Ok(Vec::new());
    }
    if each == 0 || each as usize > data.len() {
        return Err(body.fault(length.at, Problem::FieldNameLength(each)));
    }
    let each = each as usize;
    if data.len() % each != 0 {
        let len = data.len();
        return Err(body.fault(names.at, Problem::FieldNames { len, each }));
    }
    Ok(data.chunks_exact(each).map(text).collect())
}

/// Refuses a struct whose elements × fields `miMATRIX` elements (8 bytes each at
/// least) cannot fit in what is left, before looping over them.
fn check_struct_fits(body: &Cursor, elements: u64, fields: usize) -> Result<(), Fault> {
    let left = body.rest().len();
    let fits = elements
        .checked_mul(fields as u64)
        .and_then(|n| n.checked_mul(8))
        .is_some_and(|needed| needed <= left as u64);
    if fits {
        Ok(())
    } else {
        let problem = Problem::StructTooLarge {
            elements,
            fields,
            left,
        };
        Err(body.fault(body.position(), problem))
    }
}
