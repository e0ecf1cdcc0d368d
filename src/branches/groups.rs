//! A run's converged points grouped by what they are: the mode's own branch (its skeleton,
//! or its subharmonic branch), and each internal resonance apart.
//!
//! A continuation in the period or by arclength visits the internal resonances of the
//! truncated equations on its way along a skeleton (Lu & Legrand 2021, §4.1): the points of
//! one run interleave the skeleton with short excursions where a harmonic `j` meets a linear
//! frequency `omega_k`. Grouped by [`Label`], the skeleton is one group and each resonance
//! (one pair `(j, k)`) another, so that a plot can draw the skeleton as a line and each
//! resonance apart, and a table can report them separately.

use crate::branches::point::BackbonePoint;
use crate::modal::Label;

/// Converged points of one run that share a label, in the run's order.
#[derive(Debug, Clone, PartialEq)]
pub struct PointGroup<'a> {
    /// What the points are: [`Label::Skeleton`] or [`Label::Subharmonic`] for the mode's
    /// own branch, [`Label::InternalResonance`] (naming the harmonic and the linear mode it
    /// meets) for a resonance, [`Label::OffBranch`] for points off the branch the run
    /// followed (the group carries the first one's ratio), [`Label::Unverified`] for points
    /// that failed the time-domain check.
    pub label: Label,
    /// The points.
    pub points: Vec<&'a BackbonePoint>,
}

impl PointGroup<'_> {
    /// Whether the group is the mode's own branch (skeleton or subharmonic), not a resonance
    /// nor unverified points.
    pub fn is_own_branch(&self) -> bool {
        matches!(self.label, Label::Skeleton | Label::Subharmonic { .. })
    }
}

/// The converged, labelled points of `points` grouped by label: the mode's own branch first
/// (skeleton, or subharmonic), then one group per internal resonance in the order the run
/// first meets it, then the unverified points. Each point is in exactly one group; a point
/// without a label (a run that did not label, or not converged) is in none.
pub fn group_by_label(points: &[BackbonePoint]) -> Vec<PointGroup<'_>> {
    let mut groups: Vec<PointGroup<'_>> = Vec::new();
    for p in points.iter().filter(|p| p.converged()) {
        let Some(label) = &p.label else {
            continue;
        };
        // Off-branch points form one group, whatever their ratios.
        let same = |g: &PointGroup<'_>| match (&g.label, label) {
            (Label::OffBranch { .. }, Label::OffBranch { .. }) => true,
            (a, b) => a == b,
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.points.push(p),
            None => groups.push(PointGroup {
                label: label.clone(),
                points: vec![p],
            }),
        }
    }
    // Stable: resonances keep the order in which the run met them.
    groups.sort_by_key(|g| match g.label {
        Label::Skeleton | Label::Subharmonic { .. } => 0,
        Label::InternalResonance { .. } => 1,
        Label::OffBranch { .. } => 2,
        Label::Unverified => 3,
    });
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(step: usize, label: Option<Label>, converged: bool) -> BackbonePoint {
        BackbonePoint::for_test(step, 4.0 - 0.01 * step as f64, label, converged)
    }

    #[test]
    fn resonances_are_grouped_apart_from_the_skeleton() {
        let h3 = Label::InternalResonance {
            harmonic: 3,
            mode: 2,
            omega: 4.7,
        };
        let h5 = Label::InternalResonance {
            harmonic: 5,
            mode: 3,
            omega: 7.8,
        };
        let points = vec![
            point(0, Some(h5.clone()), true),
            point(1, Some(Label::Skeleton), true),
            point(2, Some(h3.clone()), true),
            point(3, Some(Label::Skeleton), true),
            point(4, Some(h3.clone()), true),
            point(5, Some(Label::Skeleton), false),
            point(6, None, true),
            point(7, Some(Label::Unverified), true),
        ];
        let groups = group_by_label(&points);
        let labels: Vec<&Label> = groups.iter().map(|g| &g.label).collect();
        assert_eq!(labels, [&Label::Skeleton, &h5, &h3, &Label::Unverified]);
        let steps = |g: &PointGroup| g.points.iter().map(|p| p.step).collect::<Vec<_>>();
        assert_eq!(steps(&groups[0]), [1, 3]);
        assert_eq!(steps(&groups[1]), [0]);
        assert_eq!(steps(&groups[2]), [2, 4]);
        assert_eq!(steps(&groups[3]), [7]);
        assert!(groups[0].is_own_branch() && !groups[1].is_own_branch());
        assert!(!groups[3].is_own_branch());
        // Every converged, labelled point is in exactly one group.
        let total: usize = groups.iter().map(|g| g.points.len()).sum();
        assert_eq!(total, 6);
        assert!(group_by_label(&[]).is_empty());
    }
}
