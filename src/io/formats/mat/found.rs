//! What the reader collects: channels, named as MATLAB would index them, and notes
//! on what it skipped.

use crate::io::formats::{Abscissa, Channel, Samples};

/// The channels and notes of one file, in file order.
#[derive(Debug, Default)]
pub(super) struct Found {
    pub channels: Vec<Channel>,
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
    /// order): one channel for a vector or scalar, else one per column, named
    /// `name(:,j)` (`name(:,j,k)` for an N-d array), 1-based.
    pub(super) fn add_array(
        &mut self,
        name: &str,
        sizes: &[i64],
        re: Vec<f64>,
        im: Option<Vec<f64>>,
    ) {
        if sizes.iter().filter(|&&d| d > 1).count() <= 1 {
            self.add(name.to_string(), samples(re, im));
            return;
        }
        let rows = sizes[0].max(1) as usize;
        let columns = re.len() / rows;
        for column in 0..columns {
            let range = column * rows..(column + 1) * rows;
            let im = im.as_ref().map(|im| im[range.clone()].to_vec());
            let label = column_label(column, &sizes[1..]);
            self.add(
                format!("{name}(:,{label})"),
                samples(re[range].to_vec(), im),
            );
        }
    }

    fn add(&mut self, name: String, samples: Samples) {
        self.channels.push(Channel {
            name,
            unit: String::new(),
            abscissa: Abscissa::Index,
            samples,
            first_line: None,
        });
    }

    /// Notes each name that more than one channel has (MATLAB itself cannot hold
    /// two variables of one name; a file can).
    pub(super) fn note_duplicates(&mut self) {
        let mut seen = std::collections::HashSet::new();
        let mut twice = Vec::new();
        for channel in &self.channels {
            if !seen.insert(channel.name.as_str()) {
                twice.push(channel.name.clone());
            }
        }
        for name in twice {
            self.notes.push(format!(
                "`{name}` is in the file more than once; each is kept"
            ));
        }
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
fn column_label(mut column: usize, trailing: &[i64]) -> String {
    let mut indices = Vec::with_capacity(trailing.len());
    for &size in trailing {
        let size = size.max(1) as usize;
        indices.push((column % size + 1).to_string());
        column /= size;
    }
    indices.join(",")
}
