//! The scene one run simulates, and what a run reports. Engine types only: no config or CLI
//! types reach the integrators.
//!
//! Buildings are single-degree-of-freedom oscillators now. A multi-storey shear building adds a
//! floor list per building and a contact list per shared floor level; the integrators already take
//! the whole `Pair` and a state vector, so the solver interface (`cpu::simulate`) stays the same.

use crate::physics::contact::Contact;

/// Standard gravity, m/s^2 (the gravity loads of P-Delta; the factor of PEER files,
/// where the records re-export it).
pub const G: f64 = 9.80665;

/// One lumped mass on a spring and dashpot to the ground (one floor, or a whole SDOF building).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oscillator {
    /// kg
    pub m: f64,
    /// N/m
    pub k: f64,
    /// N s/m
    pub c: f64,
}

impl Oscillator {
    /// From mass (kg), natural period (s) and viscous damping ratio:
    /// `k = m (2 pi / T)^2`, `c = 2 xi sqrt(k m)`.
    pub fn from_period(m: f64, period: f64, xi: f64) -> Oscillator {
        let w = 2.0 * std::f64::consts::PI / period;
        let k = m * w * w;
        Oscillator {
            m,
            k,
            c: 2.0 * xi * (k * m).sqrt(),
        }
    }

    /// Kinetic plus strain energy at displacement `u` and velocity `v`, J.
    pub fn energy(&self, u: f64, v: f64) -> f64 {
        0.5 * (self.m * v * v + self.k * u * u)
    }

    /// Bound on the oscillator's fastest rate (1/s): `sqrt(k/m) + c/m`, as
    /// [`crate::physics::contact::Contact::local_rate`] bounds the contact's.
    pub fn rate(&self) -> f64 {
        (self.k / self.m).sqrt() + self.c / self.m
    }

    /// A free mass (no spring, no dashpot): for isolated-collision problems.
    pub fn free(m: f64) -> Oscillator {
        Oscillator { m, k: 0.0, c: 0.0 }
    }
}

/// Two adjacent buildings, building 1 left of building 2, a clear gap, one contact element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    pub b1: Oscillator,
    pub b2: Oscillator,
    /// m, >= 0
    pub gap: f64,
    pub contact: Contact,
}

impl Pair {
    /// The fastest rate of the two structures (1/s). Substeps in contact resolve it as well as
    /// the contact's: a very stiff building (T = 1e-4 s) made RK4 unstable at steps sized by
    /// the contact alone.
    pub fn structural_rate(&self) -> f64 {
        self.b1.rate().max(self.b2.rate())
    }

    pub fn m_eff(b1: &Oscillator, b2: &Oscillator) -> f64 {
        b1.m * b2.m / (b1.m + b2.m)
    }
}

/// Ground acceleration `ag(t)`: samples `scale * accel[i]` at `t0 + i dt`, linear in between,
/// then a ramp to 0 one `dt` after the last sample and 0 for `tail` seconds of free vibration.
#[derive(Debug, Clone, Copy)]
pub struct Forcing<'a> {
    /// m/s^2
    pub accel: &'a [f64],
    pub dt: f64,
    pub t0: f64,
    pub scale: f64,
    /// Free vibration after the record, s.
    pub tail: f64,
}

impl Forcing<'_> {
    /// Number of `dt` intervals simulated.
    pub fn intervals(&self) -> usize {
        let tail = if self.tail > 0.0 {
            (self.tail / self.dt - 1e-9).ceil() as usize
        } else {
            0
        };
        self.accel.len().saturating_sub(1) + tail
    }

    /// Scaled sample `i` (0 past the record).
    #[inline]
    pub fn sample(&self, i: usize) -> f64 {
        self.accel.get(i).map_or(0.0, |a| a * self.scale)
    }

    pub fn t_end(&self) -> f64 {
        self.t0 + self.intervals() as f64 * self.dt
    }
}

/// Initial displacements and velocities (relative to the ground).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Initial {
    pub u1: f64,
    pub v1: f64,
    pub u2: f64,
    pub v2: f64,
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Status {
    #[default]
    Ok,
    /// The state became NaN or infinite.
    NonFinite,
    /// The step budget ran out (or the substep count a record step needed exceeded its cap).
    StepLimit,
    /// A storey's drift ratio reached the collapse limit: the run ended there (physics.md
    /// section 10). Not a failure: the run's outputs are its motion up to the collapse.
    Collapsed,
}

impl Status {
    pub fn key(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::NonFinite => "non_finite",
            Status::StepLimit => "step_limit",
            Status::Collapsed => "collapsed",
        }
    }

    /// A run that failed (its outputs are not a result): neither `ok` nor `collapsed`.
    pub fn failed(self) -> bool {
        !matches!(self, Status::Ok | Status::Collapsed)
    }
}

/// Per-run results. Peaks are over the whole simulated time.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunOutput {
    pub status: Status,
    pub impacts: u32,
    /// N
    pub peak_force: f64,
    /// m
    pub peak_penetration: f64,
    /// max |u1|, m
    pub peak_u1: f64,
    /// max |u2|, m
    pub peak_u2: f64,
    /// max |absolute acceleration| of building 1 and 2 (relative plus the ground's), m/s^2,
    /// where the run tracked it (a row of two one-storey buildings reports it,
    /// [`crate::physics::solver::simulate_tracking_accel`]); 0 otherwise.
    pub peak_accel: [f64; 2],
    /// Approach speed `v0` of the impact with the largest peak force, m/s (0 if none).
    pub impact_velocity: f64,
    /// Onset time of the first impact, s (None if no impact).
    pub first_impact: Option<f64>,
    /// Total time in contact, s.
    pub contact_time: f64,
    /// Net work of the contact force on the relative motion (energy taken out by impacts), J.
    pub dissipated_energy: f64,
    /// Integration work beyond the exact free steps: RK4 substeps (fast scheme, both backends)
    /// or trial steps (reference). 0 for a run that never came near contact.
    pub substeps: u64,
    /// Record steps taken whole by the exact free propagator (fast scheme).
    pub free_steps: u64,
    /// Record steps settled by a shared free response instead (fast scheme on the CPU): those
    /// before the run's first possible contact, and those after it ended early because the
    /// rest of the record could neither close its gap nor raise its peaks.
    pub shared_steps: u64,
    /// The run's energy balance, where it was asked for (always with the reference scheme).
    pub energy: Option<EnergyBalance>,
}

/// Energy balance of a run, J: what the ground put in against what the run holds and spent.
/// `initial + input = kinetic + strain + damping + contact work`, where the contact work is
/// [`RunOutput::dissipated_energy`] (plus what a contact still stores at the end).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyBalance {
    /// `-int ag (m1 v1 + m2 v2) dt`: work of the ground motion on the relative motion.
    pub input: f64,
    /// `int (c1 v1^2 + c2 v2^2) dt`: work of the structural dampers.
    pub damping: f64,
    /// `(initial + input - kinetic - strain - damping - contact work) / scale`, where the scale
    /// is the largest `initial + input` reached during the run (0 for a run that never moves).
    pub residual: f64,
}

impl EnergyBalance {
    /// The balance of a run that started with `initial` J, took `input` from the ground, spent
    /// `damping` in the dampers and `contact_work` in the contact, and holds `held` (kinetic plus
    /// strain) at the end; `peak` is the largest `initial + input` seen.
    pub fn close(
        initial: f64,
        input: f64,
        damping: f64,
        contact_work: f64,
        held: f64,
        peak: f64,
    ) -> EnergyBalance {
        let scale = peak.max(initial);
        let r = initial + input - held - damping - contact_work;
        EnergyBalance {
            input,
            damping,
            residual: if scale > 0.0 { r / scale } else { 0.0 },
        }
    }
}
