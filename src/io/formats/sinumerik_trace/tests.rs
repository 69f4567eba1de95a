use std::path::{Path, PathBuf};

use super::*;
use crate::io::formats::Samples;

fn shared() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/formats/sinumerik/freq_trace.XML")
}

#[test]
fn the_shared_file_reads_as_a_closed_speed_loop() {
    let m = read_measurement(&shared()).unwrap();
    assert_eq!(m.sample_time_s, 125e-6);
    assert_eq!(
        response::measured_loop(&m),
        Ok(response::MeasuredLoop::SpeedClosed)
    );
    let r = response::stored_response(&m).unwrap();
    assert_eq!(r.samples_per_period, 2047);
    assert_eq!(r.lines.len(), 1022);
    let rec = read(&shared()).unwrap();
    for c in &rec.channels {
        eprintln!("{} [{}] {}", c.name, c.unit, c.samples.len());
    }
    for n in &rec.notes {
        eprintln!("note: {n}");
    }
    assert!(matches!(
        rec.channels.last().unwrap().samples,
        Samples::Complex { .. }
    ));
}
