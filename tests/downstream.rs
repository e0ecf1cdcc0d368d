//! A downstream user's first backbone: an assembly of their own, built in Rust, and one
//! documented call (`branches::compute`) with the library's defaults. Nothing here is copied
//! from the library: the method, its grid and its start come from the system.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{compute, AutoChoice, Request, TimeDomainCheck};
use nonsmooth_modes::modal::Label;
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem};

/// Two unequal bars: the first clamped at its left end, its right end facing the second
/// bar's left end across a gap; the second held at its right end by a ground spring.
fn my_assembly() -> BarSystem {
    let mut builder = AssemblyBuilder::new();
    let first = builder.add_bar(Bar::new(1.3, 1.1, 1.0).unwrap());
    let second = builder.add_bar(Bar::new(0.8, 1.6, 2.0).unwrap());
    builder.dirichlet(first.left()).unwrap();
    builder.contact(first.right(), second.left(), 1e-3).unwrap();
    builder.robin(second.right(), 1.5).unwrap();
    builder.build().unwrap()
}

#[test]
fn one_call_gives_a_checked_labelled_backbone() {
    let system = my_assembly();
    let check = TimeDomainCheck::for_system(&system);
    let run = compute(&system, &Request::new(1).checked(check)).unwrap();

    // The library chose a method and says why.
    assert!(run.auto.is_some(), "Auto records its choice");
    assert_ne!(run.auto, Some(AutoChoice::NoStartFound), "{:?}", run.auto);

    // Every converged point carries its character and label; most are motions of the bars
    // (time-domain displacement defect under 5 %) on the skeleton of NSM 1.
    let converged: Vec<_> = run.converged().collect();
    assert!(converged.len() >= 20, "{} converged", converged.len());
    assert!(converged
        .iter()
        .all(|p| p.character.is_some() && p.label.is_some()));
    let checked = converged
        .iter()
        .filter(|p| p.time_domain.is_some_and(|r| r.displacement_defect < 0.05))
        .count();
    assert!(checked >= 20, "{checked} of {} checked", converged.len());
    let skeleton = converged
        .iter()
        .filter(|p| p.label == Some(Label::Skeleton))
        .count();
    assert!(2 * skeleton > converged.len(), "{skeleton} skeleton points");

    // A contact that closes stiffens the mode: along the skeleton, the energy grows as the
    // period falls below the linear period.
    let first = converged.first().unwrap();
    let last = converged.last().unwrap();
    assert!(last.period < first.period && last.energy > first.energy);

    // A point asks its own questions without a rebuilt problem.
    let index = run.points.iter().position(|p| p.converged()).unwrap();
    let solution = run.solution(index).unwrap();
    let energy = solution.energy().unwrap();
    assert!((energy / run.points[index].energy - 1.0).abs() < 1e-12);
}
