//! A unit spelled in a variable's name, as labs name their MAT-file arrays
//! (`act_pos_mot_deg`, `act_vel_mot_deg_per_s`, `act_torque_abs_nm`): offered as the
//! channel's unit when neither the map nor the file gives one, and said in a note.

/// Name endings and the unit each stands for, longest first so that `_deg_per_s` is
/// not read as `_s`. `_nm` is newton metres, as robot and drive recordings use it (a
/// length in nanometres is rarely a variable's unit); the role's check refuses a
/// wrong guess by its quantity.
const ENDINGS: &[(&str, &str)] = &[
    ("_deg_per_s", "deg/s"),
    ("_rad_per_s", "rad/s"),
    ("_mm_per_s", "mm/s"),
    ("_m_per_s", "m/s"),
    ("_degps", "deg/s"),
    ("_radps", "rad/s"),
    ("_rpm", "rpm"),
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_rev", "rev"),
    ("_mm", "mm"),
    ("_um", "µm"),
    ("_mnm", "mN·m"),
    ("_nm", "N·m"),
    ("_ms", "ms"),
    ("_us", "µs"),
    ("_hz", "Hz"),
    ("_ma", "mA"),
    ("_s", "s"),
];

/// The unit a channel's name ends in, if any: `rec.act_pos_mot_deg(1,:)` → `deg`.
/// The last part of the name is read (after the last `.`, before an index `(…)`),
/// ignoring case.
pub fn unit_in_name(channel: &str) -> Option<&'static str> {
    let base = channel.split('(').next().unwrap_or(channel);
    let last = base.rsplit('.').next().unwrap_or(base).to_ascii_lowercase();
    ENDINGS
        .iter()
        .find(|(ending, _)| last.len() > ending.len() && last.ends_with(ending))
        .map(|&(_, unit)| unit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::formats::units;

    #[test]
    fn the_robot_files_names_give_their_units() {
        let cases = [
            ("rec.act_pos_mot_deg(1,:)", Some("deg")),
            ("rec.act_vel_se_deg_per_s(3,:)", Some("deg/s")),
            ("rec.act_torque_abs_nm(1,:)", Some("N·m")),
            ("rec.time_cont", None),
            ("qm", None),
            ("speed_rpm", Some("rpm")),
            ("t_S", Some("s")),
            ("_deg", None),
            ("a.b_mm.c", None),
        ];
        for (name, unit) in cases {
            assert_eq!(unit_in_name(name), unit, "{name}");
        }
    }

    #[test]
    fn every_unit_offered_is_one_rtid_reads() {
        for (ending, unit) in ENDINGS {
            assert!(units::parse(unit).is_ok(), "{ending}: {unit}");
        }
    }
}
