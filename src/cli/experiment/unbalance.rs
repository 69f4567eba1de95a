//! `rtid experiment unbalance`.

use super::check::positive;
use super::fluctuation::{run_test, RunArgs};
use super::Common;
use rtid::experiments::fluctuation::{FluctuationTest, DEFAULT_UNBALANCE};

pub const LONG_ABOUT: &str = "\
Influence of an unbalance mass (paper §4.5, Fig. 14): the table is mounted vertically \
with a mass offset from its axis (gravity torque −m·g·e·sin(θt + ψ)); the servo, in \
the parameter set's loop (semi-closed in the presets; --loop overrides it), turns it at \
a constant 360°/min through one revolution each way, as in the fluctuation test. The mass and radius are the parameters' unbalance_mass and \
unbalance_radius when set, else 10 kg at 0.1 m, or --mass-kg/--radius-m.

Outputs, in --out DIR: unbalance.json/.csv, unbalance.svg (deviation θt − θm·Rg·Rw over \
table angle per direction) and unbalance-spectrum.svg. Printed: as for fluctuation, plus \
the step: the largest change of the deviation across 0.5° of table angle and where it \
happens. Where the unbalance moment overcomes the drive's friction the table crosses the \
backlash: a worm gear shows a step of about its lost motion (≈ 33″) twice per revolution \
and direction; a preloaded roller gear cam shows none. Every step of at least half the \
largest is listed, located to a fraction of a degree (where an ideal step with the same \
area under the curve would stand, in a ±5° window): `rtid identify` fits the table friction \
ft to these angles. --noise-arcsec adds Gaussian noise to the table angle readings.

Example:
  rtid experiment unbalance --preset worm-gear --out runs/worm
  rtid experiment unbalance --preset roller-gear-cam --mass-kg 20 --radius-m 0.15 --out runs/roller";

/// Arguments of `rtid experiment unbalance`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub run: RunArgs,
    /// Table speed, degrees per minute.
    #[arg(long, value_name = "DEG_PER_MIN", default_value_t = 360.0)]
    pub speed_deg_per_min: f64,
    /// Unbalance mass, kg (default: the parameters' unbalance_mass, else 10).
    #[arg(long, value_name = "KG")]
    pub mass_kg: Option<f64>,
    /// Its distance from the table axis, m (default: the parameters'
    /// unbalance_radius, else 0.1).
    #[arg(long, value_name = "M")]
    pub radius_m: Option<f64>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let own = p.unbalance_mass > 0.0 && p.unbalance_radius > 0.0;
    let (mass, radius) = match (a.mass_kg, a.radius_m) {
        (m, r) if own => (
            m.unwrap_or(p.unbalance_mass),
            r.unwrap_or(p.unbalance_radius),
        ),
        (m, r) => (
            m.unwrap_or(DEFAULT_UNBALANCE.0),
            r.unwrap_or(DEFAULT_UNBALANCE.1),
        ),
    };
    let test = FluctuationTest {
        unbalance: Some((
            positive(mass, "--mass-kg")?,
            positive(radius, "--radius-m")?,
        )),
        ..a.run.test(a.speed_deg_per_min)?
    };
    a.common.create_out()?;
    run_test(&a.common, &p, &test, &a.run)
}
