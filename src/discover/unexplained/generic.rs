//! The generic alternatives' results, and what the report says where one of them leads.

use super::spans::Span;
use super::torque_response::Added;
use super::{Context, Scored, knocks, outliers, slope_noise};

/// A generic alternative's result on a channel.
#[derive(Clone)]
pub(super) struct Generic {
    pub channel: usize,
    pub kind: GenericKind,
    pub scored: Scored,
}

/// What a generic alternative is: it can hold "anything" of its shape.
#[derive(Clone, PartialEq)]
pub(super) enum GenericKind {
    /// A Legendre polynomial in time (the report's `where` is read off the best one).
    Polynomial,
    Autoregression,
    /// The channel's derivative with a lead's sign: the channel runs ahead of the model.
    Lead,
    /// Isolated samples far off, following nothing (`outliers`): the samples flagged.
    Outliers(Vec<usize>),
    /// A transient after each step that does not ring (`transient`): its time constants [s].
    Transient([f64; 2]),
    /// A noise of two scales (`outliers`, where the fit is not isolated outliers): the samples
    /// in the wide part, its share and its width over the core's.
    Tails {
        samples: Vec<usize>,
        share: f64,
        width: f64,
    },
    /// A noise that follows the slope (`slope_noise`): the sampling instants' jitter, its sd
    /// [s], and the channels (indices) it is shared by.
    SlopeNoise {
        seconds: f64,
        channels: Vec<usize>,
    },
    /// A torque (or a voltage) at a few isolated instants (`knocks`): the samples each starts
    /// at, and the balance.
    Knocks(Vec<usize>, Added),
}

impl GenericKind {
    /// A model of the noise, not of its mean: no term or law holds what it finds.
    pub fn is_noise(&self) -> bool {
        matches!(
            self,
            GenericKind::Outliers(_) | GenericKind::Tails { .. } | GenericKind::SlopeNoise { .. }
        )
    }
}

impl Generic {
    /// Where this alternative leads the verdict: the report's `where` and sentence, where its
    /// kind says more than the fingerprint's `unknown` does; none otherwise.
    pub fn reported(&self, ctx: &Context) -> Option<(Option<Vec<Span>>, String)> {
        let channel = &ctx.channels[self.channel];
        match &self.kind {
            GenericKind::Outliers(samples) => {
                let (spans, sentence) = outliers::reported(ctx, self.channel, samples);
                Some((Some(spans), sentence))
            }
            GenericKind::Tails {
                samples,
                share,
                width,
            } => {
                let (spans, sentence) =
                    outliers::tails_reported(ctx, self.channel, samples, *share, *width);
                Some((Some(spans), sentence))
            }
            GenericKind::SlopeNoise { seconds, channels } => {
                let (spans, sentence) = slope_noise::reported(ctx, *seconds, channels);
                Some((Some(spans), sentence))
            }
            GenericKind::Knocks(starts, added) => {
                let (spans, sentence) = knocks::reported(ctx, self.channel, starts, *added);
                Some((Some(spans), sentence))
            }
            GenericKind::Lead => Some((
                None,
                format!(
                    "{channel} runs ahead of the model where it changes fast, as if that \
                     balance's fast dynamics were quicker than the model's (in the voltage \
                     balance: an inductance smaller than L, or one that falls with the \
                     current); steps of several sizes would tell a constant from a \
                     current-dependent one"
                ),
            )),
            GenericKind::Transient([fast, slow]) => Some((
                None,
                format!(
                    "after each input step {channel} relaxes in a way the model does not, with \
                     time constants of about {:.3} and {:.3} ms and no ringing: a hidden state \
                     that no term holds (in the current: a shorted turn or eddy currents in \
                     the iron; in the speed: a second mass on a damper or a fluid load); steps \
                     of several sizes and both signs would tell whether it scales with the step",
                    fast * 1e3,
                    slow * 1e3
                ),
            )),
            GenericKind::Polynomial | GenericKind::Autoregression => None,
        }
    }
}
