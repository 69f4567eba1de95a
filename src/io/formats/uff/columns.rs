//! The numbers of record 12 sorted into their columns as they are read.

/// The values of one dataset, de-interleaved on the fly: with `width` numbers per point
/// (abscissa for uneven spacing, real part, imaginary part for complex data), the
/// k-th number read goes to column `k % width`, so the interleaved sequence is never
/// held as well.
#[derive(Debug)]
pub struct Columns {
    columns: Vec<Vec<f64>>,
    next: usize,
    count: u64,
}

impl Columns {
    /// `points` is record 7's count, which the caller has checked against the bytes
    /// left in the file.
    pub fn new(width: u64, points: u64) -> Columns {
        let capacity = usize::try_from(points).unwrap_or(0);
        Columns {
            columns: (0..width).map(|_| Vec::with_capacity(capacity)).collect(),
            next: 0,
            count: 0,
        }
    }

    pub fn push(&mut self, value: f64) {
        self.columns[self.next].push(value);
        self.next = (self.next + 1) % self.columns.len();
        self.count += 1;
    }

    /// The numbers pushed so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The columns, in the order of the file.
    pub fn into_columns(self) -> Vec<Vec<f64>> {
        self.columns
    }
}

/// What a dataset's data section did that the standard does not, tolerated and told.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tolerated {
    /// ASCII lines not in the format's fixed-width columns, read as blank-separated
    /// numbers: how many, and the first.
    pub free_format_lines: Option<(usize, usize)>,
    /// 58b: a line end between the binary data and the closing `-1`, at this byte.
    pub line_end_before_closing: Option<u64>,
    /// 58b: the ID line's byte count and the one record 7 implies, when they differ.
    pub byte_count: Option<(u64, u64)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_go_round_the_columns() {
        let mut c = Columns::new(3, 2);
        for v in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0] {
            c.push(v);
        }
        assert_eq!(c.count(), 6);
        assert_eq!(
            c.into_columns(),
            vec![vec![1.0, 4.0], vec![2.0, 5.0], vec![3.0, 6.0]]
        );
    }
}
