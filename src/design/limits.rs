//! The drive's limits: the voltage a design may command, and the current and speed it may
//! drive the motor to (for a current-driven model the current is what it commands, and U is no
//! input). A design that would pass one is refused, never clipped.

use std::str::FromStr;

/// Symmetric limits: |U| ≤ voltage, |I| ≤ current, |ω| ≤ speed. The voltage may be infinite
/// (not given): a current-driven model has no voltage input.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Limits {
    #[serde(rename = "U")]
    pub voltage: f64,
    #[serde(rename = "I")]
    pub current: f64,
    #[serde(rename = "omega")]
    pub speed: f64,
}

impl FromStr for Limits {
    type Err = String;

    /// `U=±24,I=±300,omega=±3000` (`±`, `+-` or no sign; I and omega required, U only where the
    /// voltage is the input: see [`super::Commanded::level_limit`]).
    fn from_str(text: &str) -> Result<Self, String> {
        let mut found: [Option<f64>; 3] = [None; 3];
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let Some((name, value)) = item.split_once('=') else {
                return Err(format!("'{item}': expected NAME=±VALUE (U, I or omega)"));
            };
            let slot = match name.trim() {
                "U" => 0,
                "I" => 1,
                "omega" => 2,
                other => {
                    return Err(format!(
                        "'{other}': unknown limit (the limits are U, I and omega)"
                    ));
                }
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
        match found {
            [voltage, Some(current), Some(speed)] => Ok(Self {
                voltage: voltage.unwrap_or(f64::INFINITY),
                current,
                speed,
            }),
            _ => Err(
                "give the current and speed limits, and the voltage limit for a \
                      voltage-driven model, e.g. U=±24,I=±300,omega=±3000"
                    .into(),
            ),
        }
    }
}

/// As the command line takes them; a voltage that is not limited is left out.
impl std::fmt::Display for Limits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.voltage.is_finite() {
            write!(f, "U=±{},", self.voltage)?;
        }
        write!(f, "I=±{},omega=±{}", self.current, self.speed)
    }
}

impl Limits {
    /// The limit of a model channel (`I`, `omega`); none for another channel.
    pub fn of_channel(&self, name: &str) -> Option<f64> {
        match name {
            "I" => Some(self.current),
            "omega" => Some(self.speed),
            _ => None,
        }
    }

    /// How far a prediction (channel-major, `channels` named) passes the limits: the sum over
    /// channels of the largest |x|/limit − 1 above zero; 0 when it stays within them.
    pub fn excess(&self, channels: &[&str], prediction: &[f64]) -> f64 {
        let m = prediction.len() / channels.len().max(1);
        channels
            .iter()
            .enumerate()
            .filter_map(|(c, name)| {
                let limit = self.of_channel(name)?;
                let peak = prediction[c * m..(c + 1) * m]
                    .iter()
                    .fold(0.0f64, |a, x| a.max(x.abs()));
                Some((peak / limit - 1.0).max(0.0))
            })
            .sum()
    }

    /// The peak |value| of each limited channel of a prediction.
    pub fn peaks(&self, channels: &[&str], prediction: &[f64]) -> Vec<(String, f64)> {
        let m = prediction.len() / channels.len().max(1);
        channels
            .iter()
            .enumerate()
            .filter(|(_, name)| self.of_channel(name).is_some())
            .map(|(c, name)| {
                let peak = prediction[c * m..(c + 1) * m]
                    .iter()
                    .fold(0.0f64, |a, x| a.max(x.abs()));
                (name.to_string(), peak)
            })
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
        let current_only: Limits = "I=±6,omega=±500".parse().unwrap();
        assert_eq!(current_only.voltage, f64::INFINITY);
        assert_eq!(current_only.to_string(), "I=±6,omega=±500");
        for bad in [
            "U=±24,I=±300",
            "U=±24,omega=±300",
            "U=0,I=1,omega=1",
            "V=1",
            "U=x,I=1,omega=1",
            "U=1,U=2",
        ] {
            assert!(bad.parse::<Limits>().is_err(), "{bad}");
        }
        assert!(
            (l.excess(&["I", "omega"], &[299.0, -301.0, 0.0, 10.0]) - 1.0 / 300.0).abs() < 1e-12
        );
        assert_eq!(l.excess(&["I", "omega"], &[299.0, -300.0, 0.0, 10.0]), 0.0);
    }
}
