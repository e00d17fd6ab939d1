//! The 13 joint angles, their fixed order, and the ranges they may take.

use crate::error::{finite, CoreError, Result};
use std::f64::consts::PI;

/// Number of joint angles.
pub const DOF_COUNT: usize = 13;

/// One joint angle. The discriminant is its index in [`Pose`] and in the output format (SPEC 9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(usize)]
pub enum Dof {
    TorsoY = 0,
    TorsoX,
    TorsoZ,
    RightYUp,
    RightXUp,
    RightZUp,
    RightXDown,
    RightYDown,
    LeftYUp,
    LeftXUp,
    LeftZUp,
    LeftXDown,
    LeftYDown,
}

impl Dof {
    /// All angles in index order.
    pub const ALL: [Dof; DOF_COUNT] = [
        Dof::TorsoY,
        Dof::TorsoX,
        Dof::TorsoZ,
        Dof::RightYUp,
        Dof::RightXUp,
        Dof::RightZUp,
        Dof::RightXDown,
        Dof::RightYDown,
        Dof::LeftYUp,
        Dof::LeftXUp,
        Dof::LeftZUp,
        Dof::LeftXDown,
        Dof::LeftYDown,
    ];

    /// The name used in the output format.
    pub fn name(self) -> &'static str {
        DOF_NAMES[self as usize]
    }
}

/// Angle names in index order, as written in the output format (SPEC 9).
pub const DOF_NAMES: [&str; DOF_COUNT] = [
    "torso_y",
    "torso_x",
    "torso_z",
    "right_y_up",
    "right_x_up",
    "right_z_up",
    "right_x_down",
    "right_y_down",
    "left_y_up",
    "left_x_up",
    "left_z_up",
    "left_x_down",
    "left_y_down",
];

/// The 13 joint angles in radians, indexed by [`Dof`]. All zero is the rest pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose(pub [f64; DOF_COUNT]);

impl Pose {
    /// Builds a pose from a slice of exactly 13 finite angles.
    pub fn from_slice(angles: &[f64]) -> Result<Self> {
        let values: [f64; DOF_COUNT] = angles.try_into().map_err(|_| CoreError::InvalidShape {
            name: "pose",
            expected: format!("({DOF_COUNT},)"),
            got: format!("({},)", angles.len()),
        })?;
        for (dof, &v) in Dof::ALL.iter().zip(&values) {
            if !v.is_finite() {
                return Err(CoreError::NotFinite {
                    name: dof.name(),
                    value: v,
                });
            }
        }
        Ok(Pose(values))
    }

    /// The angle of one degree of freedom.
    pub fn get(&self, dof: Dof) -> f64 {
        self.0[dof as usize]
    }

    /// Sets the angle of one degree of freedom.
    pub fn set(&mut self, dof: Dof, value: f64) {
        self.0[dof as usize] = value;
    }
}

/// A closed interval `[lo, hi]` of angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
}

/// The admissible values of one angle: one interval, or the union of two disjoint ones
/// (the thesis' x_up is `[0, pi/3] U [pi/1.4, pi]`).
#[derive(Debug, Clone, PartialEq)]
pub struct DofRange {
    intervals: Vec<Interval>,
}

impl DofRange {
    /// A single interval.
    pub fn new(lo: f64, hi: f64) -> Result<Self> {
        Self::union(&[(lo, hi)])
    }

    /// A union of intervals; they must be finite, non-empty, sorted and disjoint.
    pub fn union(parts: &[(f64, f64)]) -> Result<Self> {
        if parts.is_empty() {
            return Err(CoreError::InvalidShape {
                name: "range",
                expected: "at least one interval".into(),
                got: "none".into(),
            });
        }
        let mut intervals = Vec::with_capacity(parts.len());
        for &(lo, hi) in parts {
            finite("range low end", lo)?;
            finite("range high end", hi)?;
            if lo > hi {
                return Err(CoreError::OutOfRange {
                    name: "range high end",
                    expected: ">= its low end",
                    value: hi,
                });
            }
            if let Some(prev) = intervals.last().map(|i: &Interval| i.hi) {
                if lo <= prev {
                    return Err(CoreError::OutOfRange {
                        name: "range low end",
                        expected: "above the previous interval's high end",
                        value: lo,
                    });
                }
            }
            intervals.push(Interval { lo, hi });
        }
        Ok(DofRange { intervals })
    }

    /// The intervals, sorted.
    pub fn intervals(&self) -> &[Interval] {
        &self.intervals
    }

    /// Smallest admissible value.
    pub fn lo(&self) -> f64 {
        self.intervals[0].lo
    }

    /// Largest admissible value.
    pub fn hi(&self) -> f64 {
        self.intervals[self.intervals.len() - 1].hi
    }

    /// Whether `value` lies in one of the intervals.
    pub fn contains(&self, value: f64) -> bool {
        self.intervals
            .iter()
            .any(|i| i.lo <= value && value <= i.hi)
    }

    /// The admissible value nearest to `value` (ties go to the lower interval).
    /// Idempotent: clamping an admissible value returns it unchanged.
    pub fn clamp(&self, value: f64) -> f64 {
        let mut best = self.intervals[0].lo;
        let mut best_dist = f64::INFINITY;
        for i in &self.intervals {
            let c = value.clamp(i.lo, i.hi);
            let d = (c - value).abs();
            if d < best_dist {
                best = c;
                best_dist = d;
            }
        }
        best
    }
}

/// Admissible ranges of all 13 angles.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLimits {
    ranges: Vec<DofRange>,
}

impl JointLimits {
    /// Builds limits from one range per degree of freedom, in [`Dof`] order.
    pub fn new(ranges: Vec<DofRange>) -> Result<Self> {
        if ranges.len() != DOF_COUNT {
            return Err(CoreError::InvalidShape {
                name: "limits",
                expected: format!("{DOF_COUNT} ranges"),
                got: format!("{} ranges", ranges.len()),
            });
        }
        Ok(JointLimits { ranges })
    }

    /// Ranges covering the human range of motion (SPEC 2). The default.
    pub fn anatomical() -> Self {
        let arm = [
            (-1.6, 1.6), // y_up: humeral rotation
            (-0.8, 3.1), // x_up: flexion (arm forwards, towards the camera)
            (-0.3, 3.1), // z_up: abduction (arm out sideways)
            (0.0, 2.6),  // x_down: elbow flexion
            (-1.6, 1.6), // y_down: forearm twist
        ];
        Self::from_table(&[[(-1.0, 1.0)], [(-0.4, 0.6)], [(-0.4, 0.4)]], &arm, None)
    }

    /// The thesis' initial constraints (Table 3.5-1), kept for the comparison of SPEC 7.
    /// Both arms use the right arm's y_up range: our left-arm angles are mirrored, and the
    /// thesis' left range `[0, pi]` is the mirror image of its right range `[-pi, 0]`.
    pub fn thesis() -> Self {
        let arm = [
            (-PI, 0.0),      // y_up
            (0.0, PI / 3.0), // x_up, first interval; the second is added below
            (-PI / 4.0, 0.0),
            (0.0, PI),
            (-PI, PI),
        ];
        Self::from_table(
            &[[(-PI, PI)], [(-PI, PI)], [(-PI / 4.0, 0.0)]],
            &arm,
            Some((PI / 1.4, PI)),
        )
    }

    fn from_table(
        torso: &[[(f64, f64); 1]; 3],
        arm: &[(f64, f64); 5],
        x_up_extra: Option<(f64, f64)>,
    ) -> Self {
        let mut ranges = Vec::with_capacity(DOF_COUNT);
        let single = |(lo, hi): (f64, f64)| DofRange {
            intervals: vec![Interval { lo, hi }],
        };
        for t in torso {
            ranges.push(single(t[0]));
        }
        for _side in 0..2 {
            for (k, &r) in arm.iter().enumerate() {
                let mut range = single(r);
                if k == 1 {
                    if let Some((lo, hi)) = x_up_extra {
                        range.intervals.push(Interval { lo, hi });
                    }
                }
                ranges.push(range);
            }
        }
        JointLimits { ranges }
    }

    /// The range of one angle.
    pub fn range(&self, dof: Dof) -> &DofRange {
        &self.ranges[dof as usize]
    }

    /// Whether every angle of `pose` is admissible.
    pub fn contains(&self, pose: &Pose) -> bool {
        self.ranges
            .iter()
            .zip(pose.0.iter())
            .all(|(r, &v)| r.contains(v))
    }

    /// The pose with every angle moved to its nearest admissible value.
    pub fn clamp(&self, pose: &Pose) -> Pose {
        let mut out = *pose;
        for (r, v) in self.ranges.iter().zip(out.0.iter_mut()) {
            *v = r.clamp(*v);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_dof_order() {
        for (i, dof) in Dof::ALL.iter().enumerate() {
            assert_eq!(*dof as usize, i);
        }
        assert_eq!(Dof::LeftXDown.name(), "left_x_down");
    }

    #[test]
    fn pose_rejects_wrong_length_and_nan() {
        assert!(matches!(
            Pose::from_slice(&[0.0; 12]),
            Err(CoreError::InvalidShape { .. })
        ));
        let mut v = [0.0; 13];
        v[4] = f64::NAN;
        let err = Pose::from_slice(&v).unwrap_err();
        assert_eq!(err.to_string(), "right_x_up must be finite, got NaN");
    }

    #[test]
    fn union_range_clamps_into_the_nearer_interval() {
        let r = JointLimits::thesis().range(Dof::RightXUp).clone();
        assert_eq!(r.intervals().len(), 2);
        let gap_lo = PI / 3.0;
        let gap_hi = PI / 1.4;
        assert_eq!(r.clamp(gap_lo + 0.01), gap_lo);
        assert_eq!(r.clamp(gap_hi - 0.01), gap_hi);
        assert!(!r.contains((gap_lo + gap_hi) / 2.0));
        assert_eq!(r.clamp(-1.0), 0.0);
        assert_eq!(r.clamp(4.0), PI);
    }

    #[test]
    fn clamping_is_idempotent_and_admissible() {
        let limits = JointLimits::anatomical();
        let wild = Pose([
            9.0, -9.0, 3.0, -4.0, 5.0, -2.0, 7.0, 0.1, 4.0, -3.0, 0.0, -1.0, 8.0,
        ]);
        let once = limits.clamp(&wild);
        assert!(limits.contains(&once));
        assert_eq!(limits.clamp(&once), once);
    }

    #[test]
    fn invalid_unions_are_rejected() {
        assert!(DofRange::union(&[(0.0, 1.0), (0.5, 2.0)]).is_err());
        assert!(DofRange::union(&[(1.0, 0.0)]).is_err());
        assert!(DofRange::union(&[]).is_err());
        assert!(DofRange::new(0.0, f64::INFINITY).is_err());
    }
}
