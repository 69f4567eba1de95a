//! A friction law per lane: `L` laws of one kind side by side ([`LaneLaw`]), as the
//! kernel's lanes apply them — the break-away levels gathered lane-wise for the
//! vectorised clamp, each lane's own law for the level at a sliding speed.
//! [`LaneFriction`] is [`DriveFriction`] in lanes: one variant per law.

use super::{Coulomb, DriveFriction, FrictionLaw, Stribeck};
use crate::model::lanes::Lanes;

/// `Some(law)` if the law `$f` is the pattern's variant, else `None`.
macro_rules! variant {
    ($f:expr, $pattern:pat => $law:ident) => {
        match $f {
            $pattern => Some(*$law),
            #[allow(unreachable_patterns)]
            _ => None,
        }
    };
}

/// `L` friction laws of one kind, lane `l`'s law in lane `l`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaneLaw<F, const L: usize> {
    laws: [F; L],
    /// Break-away levels of motor, shaft, table, per lane.
    breakaway: [Lanes<L>; 3],
}

impl<F: FrictionLaw, const L: usize> LaneLaw<F, L> {
    /// `laws[l]` in lane `l`.
    pub fn gather(laws: [F; L]) -> Self {
        let breakaway = [0, 1, 2].map(|b| Lanes(laws.map(|law| law.breakaway(b))));
        LaneLaw { laws, breakaway }
    }

    /// `law` in every lane.
    pub fn splat(law: F) -> Self {
        Self::gather([law; L])
    }

    /// The break-away level of body `body` in each lane.
    #[inline(always)]
    pub(crate) fn breakaway(&self, body: usize) -> Lanes<L> {
        self.breakaway[body]
    }

    /// The sliding level of body `body` at `speed` ≥ 0, each lane by its own law.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    pub(crate) fn sliding(&self, body: usize, speed: Lanes<L>) -> Lanes<L> {
        let mut out = speed.0;
        for l in 0..L {
            out[l] = self.laws[l].sliding(body, out[l]);
        }
        Lanes(out)
    }

    /// Lane `l` alone.
    pub(crate) fn lane(&self, l: usize) -> LaneLaw<F, 1> {
        LaneLaw::gather([self.laws[l]])
    }
}

/// [`DriveFriction`] in lanes: the law of `L` drives whose laws are of one kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LaneFriction<const L: usize> {
    Coulomb(LaneLaw<Coulomb, L>),
    Stribeck(LaneLaw<Stribeck, L>),
}

impl<const L: usize> LaneFriction<L> {
    /// `laws[l]` in lane `l`; `None` if the laws are not all of one kind.
    pub(crate) fn gather(laws: &[DriveFriction; L]) -> Option<Self> {
        use DriveFriction as D;
        match laws[0] {
            D::Coulomb(_) => Some(LaneFriction::Coulomb(LaneLaw::gather(each(
                laws,
                |f| variant!(f, D::Coulomb(law) => law),
            )?))),
            D::Stribeck(_) => Some(LaneFriction::Stribeck(LaneLaw::gather(each(
                laws,
                |f| variant!(f, D::Stribeck(law) => law),
            )?))),
        }
    }

    /// Lane `l` alone.
    pub(crate) fn lane(&self, l: usize) -> LaneFriction<1> {
        match self {
            LaneFriction::Coulomb(law) => LaneFriction::Coulomb(law.lane(l)),
            LaneFriction::Stribeck(law) => LaneFriction::Stribeck(law.lane(l)),
        }
    }
}

/// `pick` of every lane's law, or `None` where it gives none.
fn each<F: Copy, const L: usize>(
    laws: &[DriveFriction; L],
    pick: impl Fn(&DriveFriction) -> Option<F>,
) -> Option<[F; L]> {
    let picked: Vec<F> = laws.iter().map(pick).collect::<Option<_>>()?;
    picked.try_into().ok()
}

/// `$body` with `$law` bound to the [`LaneLaw`] of a [`LaneFriction`], one arm per
/// law: the kernel's dispatch to its generic path (as `with_law!` for one drive).
macro_rules! with_lane_law {
    ($friction:expr, $law:ident => $body:expr) => {
        match $friction {
            $crate::model::friction::lanes::LaneFriction::Coulomb($law) => $body,
            $crate::model::friction::lanes::LaneFriction::Stribeck($law) => $body,
        }
    };
}
pub(crate) use with_lane_law;
