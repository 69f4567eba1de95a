//! What the reader collects: channels, named as MATLAB would index them, and notes
//! on what it skipped. A matrix is cut into its signals once the whole file is read
//! ([`Found::finish`]), when the time bases it may be laid along are known.

use crate::io::formats::{Abscissa, Channel, Group, Samples};

/// The channels and notes of one file, in file order.
#[derive(Debug, Default)]
pub(super) struct Found {
    items: Vec<Item>,
    pub notes: Vec<String>,
}

/// A variable as read: one channel, or an array to be cut into several.
#[derive(Debug)]
enum Item {
    Channel(Channel),
    Array(Array),
}

/// A numeric array with more than one dimension above 1, values column-major.
#[derive(Debug)]
struct Array {
    name: String,
    sizes: Vec<usize>,
    re: Vec<f64>,
    im: Option<Vec<f64>>,
}

/// What the file holds once read: its channels and the arrays they were cut from.
pub(super) struct Finished {
    pub channels: Vec<Channel>,
    pub groups: Vec<Group>,
    pub notes: Vec<String>,
}

impl Found {
    pub(super) fn note(&mut self, note: String) {
        self.notes.push(note);
    }

    /// Notes that the array `name`, which is `what`, is not read.
    pub(super) fn skip(&mut self, name: &str, what: &str) {
        self.notes
            .push(format!("`{name}`: {what}, not numbers: skipped"));
    }

    /// Adds a numeric array of dimensions `sizes` (values in MATLAB's column-major
    /// order): one channel for a vector or scalar; a matrix or N-d array is cut into
    /// its signals by [`Found::finish`].
    pub(super) fn add_array(
        &mut self,
        name: &str,
        sizes: &[i64],
        re: Vec<f64>,
        im: Option<Vec<f64>>,
    ) {
        if sizes.iter().filter(|&&d| d > 1).count() <= 1 {
            self.items
                .push(Item::Channel(channel(name.to_string(), samples(re, im))));
            return;
        }
        let sizes = sizes.iter().map(|&d| d.max(1) as usize).collect();
        self.items.push(Item::Array(Array {
            name: name.to_string(),
            sizes,
            re,
            im,
        }));
    }

    /// The channels in file order, each array cut into its signals: a 2-D matrix
    /// along the dimension that is a time base's length (the length of an increasing
    /// vector of the file) when just one is, else along its longer dimension (its
    /// columns when square); an N-d array into its columns `name(:,j,k)`.
    pub(super) fn finish(mut self) -> Finished {
        let time_lengths = time_base_lengths(&self.items);
        let mut channels = Vec::new();
        let mut groups = Vec::new();
        for item in std::mem::take(&mut self.items) {
            match item {
                Item::Channel(c) => channels.push(c),
                Item::Array(a) => {
                    let in_rows = a.sizes.len() == 2 && signals_in_rows(&a.sizes, &time_lengths);
                    let first = channels.len();
                    if in_rows {
                        channels.extend(rows(&a));
                    } else {
                        channels.extend(columns(&a));
                    }
                    groups.push(Group {
                        name: a.name,
                        shape: a.sizes,
                        signals_in_rows: in_rows,
                        channels: first..channels.len(),
                    });
                }
            }
        }
        note_duplicates(&channels, &mut self.notes);
        Finished {
            channels,
            groups,
            notes: self.notes,
        }
    }
}

/// The lengths of the file's real vectors of 3 samples or more that increase
/// throughout (time bases, sample counters).
fn time_base_lengths(items: &[Item]) -> Vec<usize> {
    items
        .iter()
        .filter_map(|item| match item {
            Item::Channel(Channel {
                samples: Samples::Real(v),
                ..
            }) if v.len() >= 3 && v.windows(2).all(|w| w[1] > w[0]) => Some(v.len()),
            _ => None,
        })
        .collect()
}

/// Whether a `rows`×`columns` matrix holds its signals in rows (samples along the
/// second dimension).
fn signals_in_rows(sizes: &[usize], time_lengths: &[usize]) -> bool {
    let (rows, columns) = (sizes[0], sizes[1]);
    match (
        time_lengths.contains(&rows),
        time_lengths.contains(&columns),
    ) {
        (false, true) => true,
        (true, false) => false,
        _ => columns > rows,
    }
}

/// One channel per row `name(i,:)` of a 2-D matrix, 1-based.
fn rows(a: &Array) -> Vec<Channel> {
    let (rows, columns) = (a.sizes[0], a.sizes[1]);
    let row_of = |values: &[f64], i: usize| -> Vec<f64> {
        (0..columns).map(|j| values[j * rows + i]).collect()
    };
    (0..rows)
        .map(|i| {
            let im = a.im.as_ref().map(|im| row_of(im, i));
            let name = format!("{}({},:)", a.name, i + 1);
            channel(name, samples(row_of(&a.re, i), im))
        })
        .collect()
}

/// One channel per column `name(:,j)` (`name(:,j,k)` for an N-d array), 1-based.
fn columns(a: &Array) -> Vec<Channel> {
    let rows = a.sizes[0];
    (0..a.re.len() / rows)
        .map(|column| {
            let range = column * rows..(column + 1) * rows;
            let im = a.im.as_ref().map(|im| im[range.clone()].to_vec());
            let label = column_label(column, &a.sizes[1..]);
            let name = format!("{}(:,{label})", a.name);
            channel(name, samples(a.re[range].to_vec(), im))
        })
        .collect()
}

fn channel(name: String, samples: Samples) -> Channel {
    Channel {
        name,
        unit: String::new(),
        abscissa: Abscissa::Index,
        samples,
        first_line: None,
    }
}

/// Notes each name that more than one channel has (MATLAB itself cannot hold two
/// variables of one name; a file can).
fn note_duplicates(channels: &[Channel], notes: &mut Vec<String>) {
    let mut seen = std::collections::HashSet::new();
    let mut twice = Vec::new();
    for channel in channels {
        if !seen.insert(channel.name.as_str()) {
            twice.push(channel.name.clone());
        }
    }
    for name in twice {
        notes.push(format!(
            "`{name}` is in the file more than once; each is kept"
        ));
    }
}

fn samples(re: Vec<f64>, im: Option<Vec<f64>>) -> Samples {
    match im {
        Some(im) => Samples::Complex { re, im },
        None => Samples::Real(re),
    }
}

/// The 1-based MATLAB indices `j,k,…` of column `column` (0-based, column-major) of
/// an array whose dimensions after the first are `trailing`.
fn column_label(mut column: usize, trailing: &[usize]) -> String {
    let mut indices = Vec::with_capacity(trailing.len());
    for &size in trailing {
        indices.push((column % size + 1).to_string());
        column /= size;
    }
    indices.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn real(c: &Channel) -> &[f64] {
        match &c.samples {
            Samples::Real(v) => v,
            Samples::Complex { .. } => panic!("{} is complex", c.name),
        }
    }

    /// A 2×5 matrix [[0 1 2 3 4], [10 11 12 13 14]] in column-major order.
    fn wide() -> Vec<f64> {
        (0..5).flat_map(|j| [j as f64, 10.0 + j as f64]).collect()
    }

    #[test]
    fn a_wide_matrix_gives_its_rows_and_a_tall_one_its_columns() {
        let mut found = Found::default();
        found.add_array("w", &[2, 5], wide(), None);
        found.add_array("tall", &[3, 2], vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0], None);
        let done = found.finish();
        let names: Vec<&str> = done.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["w(1,:)", "w(2,:)", "tall(:,1)", "tall(:,2)"]);
        assert_eq!(real(&done.channels[1]), [10.0, 11.0, 12.0, 13.0, 14.0]);
        assert_eq!(real(&done.channels[3]), [4.0, 5.0, 6.0]);
        let shapes: Vec<(&str, bool, usize)> = done
            .groups
            .iter()
            .map(|g| (g.name.as_str(), g.signals_in_rows, g.channels.len()))
            .collect();
        assert_eq!(shapes, [("w", true, 2), ("tall", false, 2)]);
        assert_eq!(done.groups[0].spelling(), "w(i,:), i = 1…2");
    }

    #[test]
    fn a_time_bases_length_decides_over_the_longer_dimension() {
        let mut found = Found::default();
        // 4×3: columns are longer, but the time base has 3 samples: signals in rows.
        found.add_array("m", &[4, 3], (0..12).map(f64::from).collect(), None);
        found.add_array("t", &[3, 1], vec![0.0, 0.1, 0.2], None);
        let done = found.finish();
        assert!(done.groups[0].signals_in_rows);
        assert_eq!(real(&done.channels[0]), [0.0, 4.0, 8.0]);
        // A vector that does not increase is no time base.
        let mut found = Found::default();
        found.add_array("m", &[4, 3], (0..12).map(f64::from).collect(), None);
        found.add_array("gains", &[3, 1], vec![5.0, 1.0, 2.0], None);
        assert!(!found.finish().groups[0].signals_in_rows);
    }

    #[test]
    fn a_complex_wide_matrix_keeps_both_parts_per_row() {
        let mut found = Found::default();
        let im: Vec<f64> = wide().iter().map(|v| -v).collect();
        found.add_array("h", &[2, 5], wide(), Some(im));
        let done = found.finish();
        let Samples::Complex { re, im } = &done.channels[1].samples else {
            panic!("not complex");
        };
        assert_eq!(re, &[10.0, 11.0, 12.0, 13.0, 14.0]);
        assert_eq!(im, &[-10.0, -11.0, -12.0, -13.0, -14.0]);
    }
}
