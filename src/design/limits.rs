//! The drive's limits: the voltage a design may command, the current and speed it may drive the
//! motor to, and for a position loop the travel its reference may ask (for a current-driven model
//! the current is what it commands, and U is no input). A design that would pass one is refused,
//! never clipped.

use std::str::FromStr;

/// Symmetric limits: |U| ≤ voltage, |I| ≤ current, |ω| ≤ speed, |q| ≤ position. A limit not
/// given is infinite; which a design needs depends on what its model is driven by
/// ([`super::Commanded::required_limits`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Limits {
    #[serde(rename = "U")]
    pub voltage: f64,
    #[serde(rename = "I")]
    pub current: f64,
    #[serde(rename = "omega")]
    pub speed: f64,
    /// The travel about q = 0 a position loop's reference and its axis stay within.
    #[serde(rename = "q")]
    pub position: f64,
    /// A position loop's force (c_g times its controller's output): below the saturation it
    /// keeps the loop in its linear range.
    pub force: f64,
}

/// The names the command line takes, in the order of [`Limits::values`].
pub const LIMIT_NAMES: [&str; 5] = ["U", "I", "omega", "q", "force"];

impl FromStr for Limits {
    type Err = String;

    /// `U=±24,I=±300,omega=±3000` or for a position loop `q=±0.1,omega=±0.5[,force=±300]`
    /// (`±`, `+-` or no sign). Which must be given is checked against the model ([`super::Commanded`]).
    fn from_str(text: &str) -> Result<Self, String> {
        let mut found: [Option<f64>; 5] = [None; 5];
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let Some((name, value)) = item.split_once('=') else {
                return Err(format!(
                    "'{item}': expected NAME=±VALUE ({})",
                    LIMIT_NAMES.join(", ")
                ));
            };
            let Some(slot) = LIMIT_NAMES.iter().position(|n| *n == name.trim()) else {
                return Err(format!(
                    "'{}': unknown limit (the limits are {})",
                    name.trim(),
                    LIMIT_NAMES.join(", ")
                ));
            };
            let number = value.trim();
            let number = number
                .strip_prefix('±')
                .or_else(|| number.strip_prefix("+-"))
                .unwrap_or(number);
            let v: f64 = number
                .parse()
                .map_err(|_| format!("{name}={value}: '{number}' is not a number"))?;
            if !(v > 0.0 && v.is_finite()) {
                return Err(format!("{name}={value}: a limit must be a positive number"));
            }
            if found[slot].replace(v).is_some() {
                return Err(format!("{name} is limited twice"));
            }
        }
        if found.iter().all(Option::is_none) {
            return Err("give the drive's limits, e.g. U=±24,I=±300,omega=±3000".into());
        }
        let [voltage, current, speed, position, force] = found.map(|v| v.unwrap_or(f64::INFINITY));
        Ok(Self {
            voltage,
            current,
            speed,
            position,
            force,
        })
    }
}

/// As the command line takes them; a quantity that is not limited is left out.
impl std::fmt::Display for Limits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let given: Vec<String> = LIMIT_NAMES
            .iter()
            .zip(self.values())
            .filter(|(_, v)| v.is_finite())
            .map(|(name, v)| format!("{name}=±{v}"))
            .collect();
        write!(f, "{}", given.join(","))
    }
}

impl Limits {
    /// No limit at all: what the fixed experiments are scored under and the figure's fits.
    pub fn open() -> Self {
        Self {
            voltage: f64::INFINITY,
            current: f64::INFINITY,
            speed: f64::INFINITY,
            position: f64::INFINITY,
            force: f64::INFINITY,
        }
    }

    /// The limits in the order of [`LIMIT_NAMES`].
    pub fn values(&self) -> [f64; 5] {
        [
            self.voltage,
            self.current,
            self.speed,
            self.position,
            self.force,
        ]
    }

    /// Refuses limits that leave out one of `needed` (names of [`LIMIT_NAMES`]), saying `why`.
    pub fn require(&self, needed: &[&str], why: &str) -> Result<(), String> {
        let missing: Vec<&str> = needed
            .iter()
            .copied()
            .filter(|n| {
                LIMIT_NAMES
                    .iter()
                    .zip(self.values())
                    .any(|(name, v)| name == n && !v.is_finite())
            })
            .collect();
        if missing.is_empty() {
            return Ok(());
        }
        let meaning = |n: &str| match n {
            "U" => "U (the voltage)",
            "I" => "I (the current)",
            "omega" => "omega (the speed)",
            "q" => "q (the travel)",
            _ => "force",
        };
        let missing: Vec<&str> = missing.into_iter().map(meaning).collect();
        Err(format!(
            "{} not limited: {why} needs {}",
            missing.join(" and "),
            needed
                .iter()
                .map(|n| format!("{n}=±VALUE"))
                .collect::<Vec<_>>()
                .join(",")
        ))
    }

    /// The limit of a model channel (`I`, `omega`, `q`, `force`); none for another channel.
    pub fn of_channel(&self, name: &str) -> Option<f64> {
        match name {
            "I" => Some(self.current),
            "omega" => Some(self.speed),
            "q" => Some(self.position),
            "force" => Some(self.force),
            _ => None,
        }
    }

    /// The limited series of a prediction (channel-major, `channels` named, at `times`): each
    /// limited channel, and for a position q also the axis's speed, its backward difference
    /// between samples, limited as `omega`.
    fn limited<'a>(
        &self,
        channels: &[&'a str],
        prediction: &[f64],
        times: &[f64],
    ) -> Vec<(&'a str, f64)> {
        let m = prediction.len() / channels.len().max(1);
        let peak = |x: &[f64]| x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut out = Vec::new();
        for (c, &name) in channels.iter().enumerate() {
            let series = &prediction[c * m..(c + 1) * m];
            if self.of_channel(name).is_some() {
                out.push((name, peak(series)));
            }
            if name == "q" && !channels.contains(&"omega") {
                let speed = (1..m.min(times.len()))
                    .map(|i| ((series[i] - series[i - 1]) / (times[i] - times[i - 1])).abs())
                    .fold(0.0f64, f64::max);
                out.push(("omega", speed));
            }
        }
        out
    }

    /// How far a prediction (channel-major, `channels` named, at `times`) passes the limits:
    /// the sum over limited series of the largest |x|/limit − 1 above zero; 0 when it stays
    /// within them.
    pub fn excess(&self, channels: &[&str], prediction: &[f64], times: &[f64]) -> f64 {
        self.limited(channels, prediction, times)
            .into_iter()
            .filter_map(|(name, peak)| Some((peak / self.of_channel(name)? - 1.0).max(0.0)))
            .sum()
    }

    /// The peak |value| of each limited series of a prediction.
    pub fn peaks(
        &self,
        channels: &[&str],
        prediction: &[f64],
        times: &[f64],
    ) -> Vec<(String, f64)> {
        self.limited(channels, prediction, times)
            .into_iter()
            .map(|(name, peak)| (name.to_string(), peak))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_parse_and_refuse() {
        let l: Limits = "U=±24, I=+-300,omega=3000".parse().unwrap();
        assert_eq!((l.voltage, l.current, l.speed), (24.0, 300.0, 3000.0));
        assert_eq!(l.position, f64::INFINITY);
        let current_only: Limits = "I=±6,omega=±500".parse().unwrap();
        assert_eq!(current_only.voltage, f64::INFINITY);
        assert_eq!(current_only.to_string(), "I=±6,omega=±500");
        let travel: Limits = "q=±0.1,omega=±0.5".parse().unwrap();
        assert_eq!((travel.position, travel.speed), (0.1, 0.5));
        assert!(travel.require(&["q", "omega"], "a position loop").is_ok());
        let err = travel
            .require(&["U", "I", "omega"], "a voltage")
            .unwrap_err();
        assert!(
            err.starts_with("U (the voltage) and I (the current) not limited"),
            "{err}"
        );
        for bad in ["", "U=0,I=1,omega=1", "V=1", "U=x,I=1,omega=1", "U=1,U=2"] {
            assert!(bad.parse::<Limits>().is_err(), "{bad}");
        }
        let t = [0.001, 0.002];
        assert!(
            (l.excess(&["I", "omega"], &[299.0, -301.0, 0.0, 10.0], &t) - 1.0 / 300.0).abs()
                < 1e-12
        );
        assert_eq!(
            l.excess(&["I", "omega"], &[299.0, -300.0, 0.0, 10.0], &t),
            0.0
        );
    }

    #[test]
    fn a_position_s_speed_is_limited_by_its_difference() {
        let l: Limits = "q=±0.1,omega=±0.5".parse().unwrap();
        let t = [0.001, 0.002, 0.003];
        // q: 0, 0.0004, 0.0010 m: speeds 0.4 and 0.6 m/s; the force is not limited.
        let y = [0.0, 0.0004, 0.0010, 50.0, -90.0, 10.0];
        let peaks = l.peaks(&["q", "force"], &y, &t);
        assert_eq!(peaks[0], ("q".to_string(), 0.0010));
        assert!((peaks[1].1 - 0.6).abs() < 1e-9, "{peaks:?}");
        assert_eq!(peaks[2], ("force".to_string(), 90.0));
        assert!((l.excess(&["q", "force"], &y, &t) - 0.2).abs() < 1e-9);
        let held: Limits = "q=±0.1,omega=±0.5,force=±60".parse().unwrap();
        assert!((held.excess(&["q", "force"], &y, &t) - 0.7).abs() < 1e-9);
    }
}
