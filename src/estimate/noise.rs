//! The noises of the fixes the robust observer learns from its innovations: the position's
//! (its gates and the position smoothing) and the heading's (the offset's significance).

/// The noise estimate's time constant, in fixes, and its starting value, m.
const NOISE_FIXES: f64 = 50.0;
pub(super) const NOISE_START: f64 = 0.01;
/// The starting value's weight, in fixes: a noise is the mean of the samples so far and this
/// many of the starting value until there are [`NOISE_FIXES`] of them, so a receiver noisier
/// than the start is known within a second or two at 10 Hz, not after 50 fixes while its fixes
/// are taken for jumps and coasted through.
const NOISE_PRIOR_FIXES: f64 = 10.0;
/// The heading noise's starting value, rad (0.1°, a dual-antenna receiver's).
pub(super) const HEADING_NOISE_START: f64 = 0.1 * std::f64::consts::PI / 180.0;

/// A noise's variance learnt from samples that are each the difference of two of its draws
/// (variance 2σ²): the mean of the samples and [`NOISE_PRIOR_FIXES`] of the starting value,
/// then over the last [`NOISE_FIXES`]; each sample clipped at 4 σ so that a jump's onset
/// barely moves it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Noise {
    /// Variance of one draw.
    pub(super) var: f64,
    /// Samples learnt from (up to [`NOISE_FIXES`]).
    samples: f64,
}

impl Noise {
    pub(super) fn new(sigma: f64) -> Self {
        Noise {
            var: sigma * sigma,
            samples: 0.0,
        }
    }

    pub(super) fn learn(&mut self, sample: f64) {
        self.samples = (self.samples + 1.0).min(NOISE_FIXES);
        let fixes = (self.samples + NOISE_PRIOR_FIXES).min(NOISE_FIXES);
        let s = (sample * sample).min(16.0 * 2.0 * self.var) / 2.0;
        self.var += (s - self.var) / fixes;
    }

    pub(super) fn sigma(&self) -> f64 {
        self.var.sqrt()
    }
}
