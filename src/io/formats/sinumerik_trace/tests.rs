use std::path::{Path, PathBuf};

use super::*;
use crate::io::formats::Samples;

fn shared() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/formats/sinumerik/freq_trace.XML")
}

/// The shared file's own scalars, as its README states them, and the spectra's
/// lines: the frequency step of its vector is its bandwidth over its lines.
#[test]
fn the_shared_file_reads_as_a_closed_speed_loop() {
    let m = read_measurement(&shared()).unwrap();
    assert_eq!(m.sample_time_s, 125e-6);
    assert_eq!(m.excitation.prbs_order, Some(11));
    assert_eq!(m.excitation.levels.len(), 2);
    for l in &m.excitation.levels {
        assert!((l.offset - 4.0 * std::f64::consts::TAU / 60.0).abs() < 1e-12);
        assert!((l.amplitude - 2.0 * std::f64::consts::TAU / 60.0).abs() < 1e-12);
    }
    assert_eq!(
        response::measured_loop(&m),
        Ok(response::MeasuredLoop::SpeedClosed)
    );
    let spectrum = m.signals[0].autospectrum.as_ref().unwrap();
    let step = spectrum.frequency_hz[1] - spectrum.frequency_hz[0];
    assert!((step - 4000.0 / 1022.0).abs() < 1e-9, "{step}");
    let r = response::stored_response(&m).unwrap();
    assert_eq!((r.samples_per_period, r.lines.len()), (2047, 1022));
    // 0 dB and a small lag at the lowest line: a loop following its setpoint.
    let (g, ph) = (20.0 * r.h[0].norm().log10(), r.h[0].arg().to_degrees());
    assert!(g.abs() < 0.05 && (-5.0..0.0).contains(&ph), "{g} dB, {ph}°");
    let rec = read(&shared()).unwrap();
    assert_eq!(rec.channels.len(), 8);
    assert!(matches!(
        rec.channels.last().unwrap().samples,
        Samples::Complex { .. }
    ));
}
