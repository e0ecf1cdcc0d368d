//! Typed errors. Every variant carries the numbers that explain it.
//!
//! Every enum here is `#[non_exhaustive]`: later versions may add variants, so a `match` on
//! one outside the crate ends with a wildcard arm.

use crate::end::{BarId, EndRef};
use thiserror::Error;

/// Serialises a value by its `Display` text (an error inside a serialised end reason).
#[cfg(feature = "serde")]
pub(crate) fn display<T: std::fmt::Display, S: serde::Serializer>(
    value: &T,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_str(value)
}

/// Errors raised while describing a bar system (bars, boundary conditions, assembly).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A physical parameter is not strictly positive and finite.
    #[error("{what} must be positive and finite, got {value}")]
    NotPositive {
        /// Which parameter (e.g. "bar length", "Signorini gap").
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A parameter is not finite (NaN or infinite).
    #[error("{what} must be finite, got {value}")]
    NotFinite {
        /// Which parameter.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// The assembly holds no bar.
    #[error("the assembly has no bar")]
    NoBars,
    /// A condition names a bar that the builder did not mint.
    #[error(
        "condition `{condition}` refers to {}, but the assembly has {bars} bar(s)",
        BarId(*.bar)
    )]
    UnknownBar {
        /// Name of the condition.
        condition: String,
        /// Index of the missing bar.
        bar: usize,
        /// Number of bars in the assembly.
        bars: usize,
    },
    /// An end has no boundary condition.
    #[error("{end} has no boundary condition")]
    UnconstrainedEnd {
        /// The free-floating end.
        end: EndRef,
    },
    /// An end has two boundary conditions.
    #[error("{end} has two boundary conditions: `{first}` and `{second}`")]
    OverconstrainedEnd {
        /// The doubly constrained end.
        end: EndRef,
        /// The first condition.
        first: String,
        /// The second condition.
        second: String,
    },
    /// A condition lists the same end twice.
    #[error("condition `{condition}` lists the {end} twice")]
    RepeatedEnd {
        /// Name of the condition.
        condition: String,
        /// The repeated end.
        end: EndRef,
    },
    /// A condition's equation count does not match its end count: each end needs one equation
    /// (a linear row or a unilateral law).
    #[error(
        "condition `{condition}` acts on {ends} end(s) but gives {rows} linear row(s) and {laws} unilateral law(s)"
    )]
    EquationCount {
        /// Name of the condition.
        condition: String,
        /// Number of ends it constrains.
        ends: usize,
        /// Number of linear rows it gives per harmonic.
        rows: usize,
        /// Number of unilateral laws (0 or 1).
        laws: usize,
    },
    /// A condition gives a coefficient (of a linear row or of its law's gap or force), an
    /// offset or a stored energy that is not finite.
    #[error("condition `{condition}` gives a non-finite {what}: {value}")]
    NonFiniteCoefficient {
        /// Name of the condition.
        condition: String,
        /// Where: "linear-row coefficient", "gap observable", "contact-force observable" or
        /// "stored energy".
        what: &'static str,
        /// The value.
        value: f64,
    },
}

/// Errors in harmonic-balance settings or evaluation points.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SettingsError {
    /// The number of harmonics is zero.
    #[error("the number of harmonics must be at least 1, got 0")]
    ZeroHarmonics,
    /// Too few time samples per harmonic to resolve the highest harmonic.
    #[error("samples per harmonic must be at least {min}, got {got}")]
    TooFewSamples {
        /// Requested samples per harmonic.
        got: usize,
        /// Smallest admissible value.
        min: usize,
    },
    /// A real-valued setting is not positive and finite.
    #[error("{what} must be positive and finite, got {value}")]
    NotPositive {
        /// Which setting.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A value that may have any sign is NaN or infinite.
    #[error("{what} must be finite, got {value}")]
    NotFinite {
        /// Which value.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A value outside the range in which the computation stays finite.
    #[error("{what} must lie in [{min:e}, {max:e}], got {value:e}")]
    OutOfRange {
        /// Which value.
        what: &'static str,
        /// The rejected value.
        value: f64,
        /// The smallest accepted value.
        min: f64,
        /// The largest accepted value.
        max: f64,
    },
    /// A vector has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    Length {
        /// Which vector.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The expected length.
        expected: usize,
    },
    /// A requested linear mode or subharmonic index is out of range.
    #[error("{what} must be at least 1, got {value}")]
    ZeroIndex {
        /// Which index.
        what: &'static str,
        /// The rejected value.
        value: usize,
    },
    /// A request names one mode and order, its method's options another
    /// ([`Request::for_method`](crate::branches::Request::for_method) builds one that agrees).
    #[error(
        "the request asks NSM {request_mode} sub {request_order}, its method's options NSM \
         {method_mode} sub {method_order}"
    )]
    MethodDisagrees {
        /// The request's mode.
        request_mode: usize,
        /// The request's order.
        request_order: usize,
        /// The mode the method's options name.
        method_mode: usize,
        /// The order the method's options name.
        method_order: usize,
    },
    /// The system has no unilateral condition, so it has no nonsmooth mode to compute.
    #[error("the system has no unilateral contact condition")]
    NoContact,
    /// A phase reference that does not move fixes no phase: the derivative in time of
    /// `what` is zero (a state of rest, or one whose contacts stay still).
    #[error("the phase reference fixes no phase: {what} do not move in time")]
    StillReference {
        /// Which part of the reference is still.
        what: &'static str,
    },
    /// The linear mode used for a seed or a normalisation moves no contact gap.
    #[error("the linear mode at omega = {omega} moves no contact gap, so it never grazes")]
    NoGrazing {
        /// Its natural frequency.
        omega: f64,
    },
    /// No start of an energy-parametrised backbone: every solve at a fixed frequency just
    /// above the linear mode's, from its grazing seed, failed or reached a motion that does
    /// not touch (the state of rest).
    #[error(
        "no start for the nonsmooth mode of the linear mode at omega = {omega}: {attempts} \
         solves at fixed frequencies just above it reached no motion in contact"
    )]
    NoStart {
        /// The linear mode's natural frequency.
        omega: f64,
        /// Solves tried.
        attempts: usize,
    },
    /// No start of a frequency-parametrised backbone: every guess tried (the linear mode's
    /// grazing seed at the asked frequency, then scaled, at higher frequencies and with the
    /// floating bars set moving) led the solver to the state of rest or did not converge.
    #[error(
        "no start for the branch at Omega = {omega}: of {attempts} solves at frequencies up \
         to {up_to}, {at_rest} reached the state of rest (a motion that does not touch) and \
         {failed} did not converge"
    )]
    StartNotFound {
        /// The asked frequency.
        omega: f64,
        /// The highest frequency tried.
        up_to: f64,
        /// Solves tried.
        attempts: usize,
        /// Solves that converged to the state of rest.
        at_rest: usize,
        /// Solves that did not converge.
        failed: usize,
    },
    /// The open-contact system has a rigid-body motion along which no contact gap closes:
    /// the bars it moves are held from one side only (a free end, or a contact that can
    /// push them but never pull them back), so they can drift away and no periodic motion
    /// touches them.
    #[error(
        "bars {bars:?} (0-based) can drift away: a rigid-body motion of theirs closes no contact \
         gap, so no periodic motion touches them; hold them from both sides (a wall, a \
         contact, a spring or a clamp)"
    )]
    Unconfined {
        /// The bars the drift moves (0-based indices).
        bars: Vec<usize>,
    },
    /// A run cannot be lifted to fewer harmonics than it has
    /// ([`branches::lift`](crate::branches::lift)).
    #[error("a run at {from} harmonics cannot be lifted to {to}: lifting adds harmonics")]
    LiftToFewerHarmonics {
        /// Harmonics of the run.
        from: usize,
        /// Harmonics asked.
        to: usize,
    },
    /// The seed's harmonic exceeds the basis.
    #[error(
        "subharmonic {subharmonic} needs harmonic {subharmonic} but the basis stops at {harmonics}"
    )]
    HarmonicOutOfRange {
        /// Requested subharmonic order.
        subharmonic: usize,
        /// Harmonics of the basis.
        harmonics: usize,
    },
    /// A natural-frequency scan would need more samples than allowed.
    #[error(
        "scanning up to omega = {omega_max} needs {samples} samples, more than the limit {limit}"
    )]
    ScanTooLong {
        /// Upper end of the requested range.
        omega_max: f64,
        /// Samples the scan would need.
        samples: usize,
        /// The limit.
        limit: usize,
    },
    /// No natural frequency of the open-contact system was found in the searched range.
    #[error("no natural frequency number {mode} found below omega = {omega_max}")]
    ModeNotFound {
        /// Requested mode number.
        mode: usize,
        /// Upper end of the searched range.
        omega_max: f64,
    },
    /// The buffers a request implies exceed the memory budget
    /// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES)).
    #[error(transparent)]
    TooLarge(#[from] OverBudget),
    /// A fundamental frequency is positive but so small that it is subnormal or that its
    /// period `2 pi / omega` overflows (see
    /// [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY)).
    #[error(
        "{what} {omega:e} is below {min:e}: it is subnormal or its period 2 pi / omega overflows"
    )]
    FrequencyTooSmall {
        /// Which frequency.
        what: &'static str,
        /// The rejected value.
        omega: f64,
        /// The smallest admissible value.
        min: f64,
    },
    /// A fundamental frequency so high that the phase `k l` of the highest harmonic's wave
    /// over a bar exceeds [`MAX_PHASE`](crate::system::MAX_PHASE): `sin(k l)` carries no
    /// significant digit there.
    #[error(
        "{what} {omega:e} is above {max:e}: the highest harmonic's phase over a bar exceeds 2^52, where sin and cos carry no significant digit"
    )]
    FrequencyTooLarge {
        /// Which frequency.
        what: &'static str,
        /// The rejected value.
        omega: f64,
        /// The largest admissible value for this problem.
        max: f64,
    },
    /// The first grazing energy `E_g` is not a positive, finite, normal number: the gap of
    /// the law that sets it is too small (its square underflows) or too large (overflows) for
    /// `f64`, and every `E / E_g` would be NaN or infinite.
    #[error(
        "the grazing energy set by law {law} (gap {gap:e}) is {energy:e}, not a positive finite normal number: rescale the gaps"
    )]
    GrazingEnergyOutOfRange {
        /// Index of the unilateral law that sets `E_g`.
        law: usize,
        /// Its gap.
        gap: f64,
        /// The energy computed.
        energy: f64,
    },
    /// A post-processed quantity came out NaN or infinite although its inputs were valid:
    /// the unknowns or the frequency are beyond the range that `f64` can evaluate.
    #[error("{what} is not finite at omega = {omega:e}")]
    NonFiniteResult {
        /// Which quantity.
        what: &'static str,
        /// The fundamental frequency.
        omega: f64,
    },
    /// An index names an item the system does not have (a bar, a unilateral law): it is not
    /// below their count.
    #[error("{what} {index} is out of range: there are {count}")]
    IndexOutOfRange {
        /// Which index.
        what: &'static str,
        /// The rejected index.
        index: usize,
        /// How many items there are (valid indices are `0..count`).
        count: usize,
    },
    /// A range given by its ends (a period or energy grid, a range of forcing frequencies)
    /// that cannot be used: empty, reversed, a single value, or ends that are not finite or
    /// not positive.
    #[error(transparent)]
    Range(#[from] BadRange),
    /// A state whose length is not a whole, positive number of blocks of its basis's
    /// coefficients (`m + 1` of a cosine basis, `2 m + 1` of a full one, for `m` harmonics):
    /// it was written for another number of harmonics, or is empty.
    #[error(
        "{what} has length {got}, not a positive multiple of the {coefficients} coefficients \
         of {harmonics} harmonics"
    )]
    StateLayout {
        /// Which state.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The harmonics it was said to have.
        harmonics: usize,
        /// Coefficients per unknown for that many harmonics (wide: it may exceed `usize`).
        coefficients: u128,
    },
    /// A request within the memory budget that the allocator refused all the same (the
    /// process has less memory than the budget left): returned instead of aborting.
    #[error("{what} needs {bytes:.3e} bytes, which the allocator refused")]
    AllocationFailed {
        /// What was requested.
        what: &'static str,
        /// Bytes asked for.
        bytes: f64,
    },
}

/// Errors of a nonlinear solve.
#[derive(Debug, Clone, PartialEq, Error)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum SolveError {
    /// The iteration budget ran out before the tolerance was met.
    #[error("no convergence after {iterations} iterations: residual norm {residual_norm:e} > tolerance {tolerance:e}")]
    MaxIterations {
        /// Iterations performed.
        iterations: usize,
        /// Residual norm reached.
        residual_norm: f64,
        /// Requested tolerance.
        tolerance: f64,
    },
    /// The (generalised) Jacobian is singular to working precision.
    #[error("singular Jacobian at iteration {iteration}: pivot {pivot} has |u_ii| / max |u_jj| = {ratio:e}")]
    SingularJacobian {
        /// Iteration at which the factorisation failed.
        iteration: usize,
        /// Index of the smallest pivot.
        pivot: usize,
        /// Ratio of that pivot to the largest.
        ratio: f64,
    },
    /// The backtracking line search found no decrease of the merit function.
    #[error("line search failed at iteration {iteration}: residual norm {residual_norm:e}, step length {step:e}")]
    LineSearch {
        /// Iteration at which it failed.
        iteration: usize,
        /// Residual norm at the start of the search.
        residual_norm: f64,
        /// Last step length tried.
        step: f64,
    },
    /// The residual norm stopped decreasing: not below `stall_ratio` times its value `window`
    /// iterations earlier (see [`NewtonOptions::stall_window`](crate::solve::NewtonOptions),
    /// and [`Dogleg::STALL_WINDOW`](crate::solve::Dogleg::STALL_WINDOW) for the dogleg).
    #[error("stagnated at iteration {iteration}: residual norm {residual_norm:e}, {earlier_residual_norm:e} {window} iterations earlier")]
    Stagnated {
        /// Iteration at which it was detected.
        iteration: usize,
        /// Residual norm then.
        residual_norm: f64,
        /// Residual norm `window` iterations earlier.
        earlier_residual_norm: f64,
        /// The window.
        window: usize,
    },
    /// The budget of residual evaluations ran out (see
    /// [`NewtonOptions::max_evaluations`](crate::solve::NewtonOptions)).
    #[error("evaluation budget of {evaluations} residuals spent at iteration {iteration}: residual norm {residual_norm:e}")]
    EvaluationBudget {
        /// Iteration at which it ran out.
        iteration: usize,
        /// Residual evaluations made.
        evaluations: usize,
        /// Residual norm at the start of that iteration's line search.
        residual_norm: f64,
    },
    /// The trust region shrank below its minimum radius.
    #[error("trust region collapsed at iteration {iteration}: radius {radius:e}, residual norm {residual_norm:e}")]
    TrustRegion {
        /// Iteration at which it collapsed.
        iteration: usize,
        /// Radius reached.
        radius: f64,
        /// Residual norm at that point.
        residual_norm: f64,
    },
    /// The residual or the Jacobian contains NaN or infinity.
    #[error("non-finite {what} at iteration {iteration}")]
    NonFinite {
        /// "residual", "Jacobian", "initial guess" or "dogleg step" (a trust-region step or
        /// radius that overflows).
        what: &'static str,
        /// Iteration at which it appeared.
        iteration: usize,
    },
    /// The unknown vector does not match the problem dimension.
    #[error("unknown vector has length {got}, the problem has dimension {expected}")]
    Dimension {
        /// Length given.
        got: usize,
        /// Problem dimension.
        expected: usize,
    },
    /// A solver option is invalid.
    #[error("solver option {what} must be positive and finite, got {value}")]
    InvalidOption {
        /// Which option.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// The solve's [`SolveMonitor`](crate::solve::SolveMonitor) cancelled it.
    #[error("solve cancelled at iteration {iteration} after {evaluations} residual evaluations")]
    Cancelled {
        /// Iteration at which it was cancelled.
        iteration: usize,
        /// Residual evaluations made.
        evaluations: usize,
    },
}

/// Errors of a continuation run.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ContinuationError {
    /// An option is invalid (non-finite, empty range, zero steps...).
    #[error("invalid continuation option {what}: {value}")]
    InvalidOption {
        /// Which option.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// Too many consecutive steps (or attempts to leave a stall) failed: the branch is lost.
    #[error(
        "continuation stalled: {failures} consecutive failed steps, last at parameter {parameter}"
    )]
    Stalled {
        /// Consecutive failures, or attempts.
        failures: usize,
        /// Parameter value of the last failure.
        parameter: f64,
    },
    /// The step of a pseudo-arclength run fell below its minimum: the branch cannot be
    /// followed further.
    #[error("step {step_size:e} below its minimum at parameter {parameter}")]
    StepBelowMinimum {
        /// The last step tried.
        step_size: f64,
        /// Parameter value of the last rejected step.
        parameter: f64,
    },
    /// A run rejected more steps than it allows
    /// ([`ArclengthOptions::max_rejections`](crate::continuation::ArclengthOptions::max_rejections)).
    #[error("{rejections} rejected steps, the last at parameter {parameter}")]
    TooManyRejections {
        /// Rejected steps, the last one included.
        rejections: usize,
        /// Parameter value of the last rejected step.
        parameter: f64,
    },
    /// The solver failed at the starting point.
    #[error("the solver failed at the starting point: {0}")]
    Start(SolveError),
    /// The bordered Jacobian that gives the tangent is singular.
    #[error("singular bordered Jacobian: no tangent at parameter {lambda}")]
    SingularTangent {
        /// Parameter value.
        lambda: f64,
    },
    /// [`Arclength::switch_branch`](crate::continuation::Arclength::switch_branch) was asked
    /// to switch where the last accepted step reported no branch point.
    #[error("no branch point between the last two accepted points (parameter {parameter})")]
    NoBranchPoint {
        /// Parameter of the current point.
        parameter: f64,
    },
    /// The corrector failed on the branch that crosses at a branch point.
    #[error("switching branches at parameter {parameter}: {error}")]
    BranchSwitch {
        /// Parameter of the branch point's estimate.
        parameter: f64,
        /// The corrector's error.
        error: SolveError,
    },
    /// The starting vector does not match the problem dimension.
    #[error("starting vector has length {got}, the problem has dimension {expected}")]
    Dimension {
        /// Length given.
        got: usize,
        /// Problem dimension.
        expected: usize,
    },
    /// The values a request implies exceed the memory budget
    /// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES)).
    #[error(transparent)]
    TooLarge(#[from] OverBudget),
    /// A parameter range or list of values that cannot be used: empty (all its values equal),
    /// reversed or with a NaN end.
    #[error(transparent)]
    Range(#[from] BadRange),
}

/// Errors of the time-domain integrator and of the periodicity check ([`crate::verify`]).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum VerifyError {
    /// A condition declares no time-domain form
    /// ([`BoundaryCondition::time_domain_form`](crate::bc::BoundaryCondition::time_domain_form)
    /// is `None`): its law in time is not known, so the system is not marched.
    #[error(
        "condition `{condition}` declares no time-domain form: the integrator does not know \
         its law in time"
    )]
    NoTimeDomainForm {
        /// Name of the condition.
        condition: String,
    },
    /// A boundary condition has a form the integrator cannot advance exactly.
    #[error("condition `{condition}` is not supported by the time-domain integrator: {reason}")]
    Unsupported {
        /// Name of the condition.
        condition: String,
        /// What is missing or unexpected.
        reason: &'static str,
    },
    /// The time step is not positive and finite.
    #[error("time step must be positive and finite, got {dt}")]
    InvalidTimeStep {
        /// The rejected step.
        dt: f64,
    },
    /// A bar's travel time `l / c` is shorter than one time step: a wave would cross it
    /// within a step, before the other end has answered.
    #[error(
        "{} has l/c = {travel_time} = {cells} steps of dt = {dt}: the time step must not \
         exceed the travel time of any bar",
        BarId(*.bar)
    )]
    NonMatchingGrid {
        /// Index of the bar.
        bar: usize,
        /// Its travel time `l / c`.
        travel_time: f64,
        /// The time step.
        dt: f64,
        /// `l / (c dt)`.
        cells: f64,
    },
    /// No time step near the requested one gives every bar an integer number of cells
    /// ([`Grid::nearest`](crate::verify::Grid::nearest), which looks for a commensurate grid;
    /// any step gives a valid grid).
    #[error("no time step between {low} and {high} gives every bar an integer number of cells")]
    NoAdmissibleGrid {
        /// Smallest step searched.
        low: f64,
        /// Largest step searched.
        high: f64,
    },
    /// A value of the initial state (or a parameter) is NaN or infinite.
    #[error("non-finite {what} in {} at index {index}: {value}", BarId(*.bar))]
    NonFinite {
        /// Which quantity.
        what: &'static str,
        /// Bar index.
        bar: usize,
        /// Index of the cell or node (0 for end values).
        index: usize,
        /// The rejected value.
        value: f64,
    },
    /// A number of a finished check is NaN or infinite: the march of a state whose values
    /// are finite but near the edge of `f64` (a huge motion, a huge gap) can overflow its
    /// norms and energies.
    #[error("the {what} of the periodicity check is not finite: {value}")]
    NonFiniteResult {
        /// Which quantity of the report.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A vector of the initial state has the wrong length.
    #[error("{what} of {} has length {got}, expected {expected}", BarId(*.bar))]
    Length {
        /// Which vector.
        what: &'static str,
        /// Bar index.
        bar: usize,
        /// Its length.
        got: usize,
        /// The expected length.
        expected: usize,
    },
    /// The number of bars of an input does not match the model.
    #[error("input describes {got} bar(s), the model has {expected}")]
    BarCount {
        /// Bars given.
        got: usize,
        /// Bars of the model.
        expected: usize,
    },
    /// A real parameter is out of its admissible range.
    #[error("{what} is out of range: {value}")]
    InvalidParameter {
        /// Which parameter.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// Two states that should share a model and a grid do not.
    #[error("the two states have different models or grids")]
    MismatchedStates,
    /// The model itself is inconsistent (an end without or with two conditions, a bad gap...).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The cells or the steps a request implies exceed the memory budget
    /// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES)).
    #[error(transparent)]
    TooLarge(#[from] OverBudget),
    /// A march would take more work than
    /// [`MAX_MARCH_WORK`](crate::verify::MAX_MARCH_WORK) wave-piece operations (its bound,
    /// see [`verify::march`](crate::verify::march)).
    #[error(
        "a march of {steps} time steps takes up to {work:.3e} wave-piece operations \
         ({per_step:.1} per step), over the limit of {limit:.3e}: march fewer periods or use \
         a longer time step"
    )]
    TooCostly {
        /// Steps of the march.
        steps: f64,
        /// Bound on the pieces taken at the ends per step, at the grid's resolution.
        per_step: f64,
        /// Bound on the pieces taken at the ends over the march.
        work: f64,
        /// [`MAX_MARCH_WORK`](crate::verify::MAX_MARCH_WORK).
        limit: f64,
    },
}

/// Why the Floquet multipliers of a point could not be computed
/// ([`stability`](crate::stability)).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum StabilityError {
    /// The one-period map could not be built or marched (an unsupported condition, a grid
    /// too large or too costly, a bad period...).
    #[error(transparent)]
    Verify(#[from] VerifyError),
    /// The monodromy matrix would have more rows than the limit: its dense eigenvalue problem
    /// costs `O(n^3)` and `8 n^2` bytes.
    #[error(
        "the monodromy matrix would have {dimension} rows ({cells_per_travel} cells per \
         shortest travel time), over the limit of {limit}: use fewer cells per travel time"
    )]
    TooLarge {
        /// Rows of the matrix: the cells and free end displacements of the grid.
        dimension: usize,
        /// The resolution asked ([`StabilityOptions::cells_per_travel`](crate::stability::StabilityOptions::cells_per_travel)).
        cells_per_travel: f64,
        /// [`MAX_DIMENSION`](crate::stability::MAX_DIMENSION).
        limit: usize,
    },
    /// The marches of the differences and corrections would take more time steps than the
    /// limit (seconds per point at most).
    #[error(
        "the stability of this point takes up to {steps:.3e} time steps of marching \
         ({dimension} coordinates, {corrections} corrections), over the limit of {limit:.3e}: \
         use fewer cells per travel time or fewer corrections"
    )]
    TooCostly {
        /// `2 n (periods' steps) (1 + corrections)`.
        steps: f64,
        /// Coordinates `n`.
        dimension: usize,
        /// [`StabilityOptions::corrections`](crate::stability::StabilityOptions::corrections).
        corrections: usize,
        /// [`MAX_MARCH_STEPS`](crate::stability::MAX_MARCH_STEPS).
        limit: f64,
    },
    /// An option is out of its range (named, with its value).
    #[error("stability option {what} must be {expected}, got {value}")]
    InvalidOption {
        /// The option.
        what: &'static str,
        /// What it must be.
        expected: &'static str,
        /// Its value.
        value: f64,
    },
    /// The state is at rest: its one-period map is linear and the relative perturbation
    /// step has no scale.
    #[error("the state is at rest (zero norm): its stability is that of the linear system")]
    AtRest,
    /// The dense eigenvalue solver did not converge.
    #[error("the eigenvalues of the {dimension} x {dimension} monodromy matrix did not converge")]
    NoEigenvalues {
        /// Rows of the matrix.
        dimension: usize,
    },
    /// The singular value decomposition of a correction step did not converge.
    #[error(
        "the singular values of the {dimension} x {dimension} correction matrix did not converge"
    )]
    NoSingularValues {
        /// Rows of the matrix.
        dimension: usize,
    },
    /// Hill's method needs rows that do not depend on the frequency: the exponent would
    /// enter a condition whose rows do (an end mass).
    #[error(
        "condition `{condition}` has rows that depend on the frequency: Hill's method does \
         not support it"
    )]
    HillUnsupported {
        /// Name of the condition.
        condition: String,
    },
    /// The Hill matrix would have more rows than the limit: each shift of its search solves
    /// a dense eigenvalue problem of that size.
    #[error(
        "the Hill matrix would have {dimension} rows, over the limit of {limit}: use fewer \
         harmonics"
    )]
    HillTooLarge {
        /// `(2 m + 1)` times the unknowns per harmonic.
        dimension: u128,
        /// [`MAX_HILL_DIMENSION`](crate::stability::MAX_HILL_DIMENSION).
        limit: usize,
    },
    /// A number of the report is NaN or infinite although every input was finite: the
    /// state's norms and energies overflow or underflow (a state scaled by about `1e300` or
    /// `1e-300`), so its defects and corrections cannot be measured.
    #[error(
        "the {what} of the stability check is not finite ({value}): the state's norms or \
         energies overflow or underflow in f64; rescale it"
    )]
    NonFiniteResult {
        /// Which number of the report.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A multiplier or a matrix entry is not finite.
    #[error("the monodromy matrix has a non-finite entry ({value}) in column {column}")]
    NonFinite {
        /// The column (perturbed coordinate).
        column: usize,
        /// The value.
        value: f64,
    },
}

/// Errors in the damping and excitation of a forced response ([`crate::forced`]).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ForcingError {
    /// A forced response needs an excitation: without one its only motion is rest.
    #[error(
        "a forced response needs at least one excitation (a force at an end or a base motion)"
    )]
    NoExcitation,
    /// The damping vector does not have one value per bar.
    #[error("damping has {got} values, expected one per bar ({expected})")]
    DampingLength {
        /// Values given.
        got: usize,
        /// Bars of the system.
        expected: usize,
    },
    /// A damping coefficient is negative or not finite.
    #[error("the damping of bar {bar} must be finite and non-negative, got {value}")]
    Damping {
        /// Index of the bar (from 0).
        bar: usize,
        /// The rejected value.
        value: f64,
    },
    /// An excitation amplitude is not finite.
    #[error("the excitation amplitude at {end} must be finite, got {value}")]
    Amplitude {
        /// The excited end.
        end: String,
        /// The rejected value.
        value: f64,
    },
    /// The end is not held by a linear condition of its own (it is free of conditions, held
    /// by a unilateral law or shared with another end), so no row carries the excitation.
    #[error("no linear condition holds {end} alone: {reason}")]
    NoConditionRow {
        /// The excited end.
        end: String,
        /// What holds it instead.
        reason: String,
    },
    /// The condition at the end cannot feel this excitation: a force at a clamped end, or a
    /// base motion at an end tied to no ground.
    #[error("{what} at {end} acts on nothing: its condition `{condition}` has no {missing} term")]
    NothingToExcite {
        /// `a force` or `a base motion`.
        what: &'static str,
        /// The excited end.
        end: String,
        /// The condition there.
        condition: String,
        /// The term the excitation needs (`strain` or `displacement`).
        missing: &'static str,
    },
}

/// Any error of the crate.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// See [`ModelError`].
    #[error(transparent)]
    Model(#[from] ModelError),
    /// See [`SettingsError`].
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// See [`SolveError`].
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// See [`ContinuationError`].
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
    /// See [`VerifyError`].
    #[error(transparent)]
    Verify(#[from] VerifyError),
    /// See [`StabilityError`].
    #[error(transparent)]
    Stability(#[from] StabilityError),
    /// See [`ForcingError`].
    #[error(transparent)]
    Forcing(#[from] ForcingError),
}

/// A request whose buffers would exceed the memory budget
/// [`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES): raised by
/// [`check_memory`](crate::fourier::check_memory) and carried by the `TooLarge` variants of
/// [`SettingsError`], [`ContinuationError`] and [`VerifyError`].
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[error(
    "{what} needs {requested_bytes:.3e} bytes ({}), more than the memory budget of {budget_bytes} bytes ({})",
    binary_size(*requested_bytes),
    binary_size(*budget_bytes as f64)
)]
pub struct OverBudget {
    /// What was requested.
    pub what: &'static str,
    /// Bytes the request needs (a float: the sizes that overflow `usize` are reported too).
    pub requested_bytes: f64,
    /// The budget in bytes.
    pub budget_bytes: u64,
}

/// `bytes` with a binary unit (`1.5 GiB`; in exponent notation beyond the largest unit).
fn binary_size(bytes: f64) -> String {
    const UNITS: [&str; 9] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB", "ZiB", "YiB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if value < 1024.0 {
        format!("{value:.1} {}", UNITS[unit])
    } else {
        format!("{value:.1e} {}", UNITS[unit])
    }
}

/// An over-budget request is a settings error.
impl From<OverBudget> for Error {
    fn from(e: OverBudget) -> Self {
        Error::Settings(e.into())
    }
}

/// What makes a range unusable ([`BadRange`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum RangeDefect {
    /// Its ends are equal (for a list of values: all its values are): a grid of several
    /// steps would compute the same point again and again, a range would hold nothing to
    /// continue in.
    Empty,
    /// Its start lies above its end where the range must rise (a range of forcing
    /// frequencies, a continuation's `(lo, hi)`): the computation would have nowhere to go.
    Reversed,
    /// A grid of fewer than two steps, which has no step to take.
    SinglePoint,
    /// An end is NaN or infinite.
    NotFinite,
    /// An end is zero or negative where the range holds periods, frequencies or energy
    /// levels, which are positive.
    NotPositive,
}

/// A range given by its two ends (and, for a grid, its number of values) that cannot be used,
/// quoted as it was given: carried by the `Range` variants of [`SettingsError`] (period and
/// energy grids, forcing frequencies) and [`ContinuationError`] (a continuation's parameter
/// range or values).
///
/// Its message names the range, its ends and steps as given, and what is wrong with them,
/// so that a user who typed `3.5` twice or `2:1` sees those numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BadRange {
    /// Which range (e.g. "period grid", "forcing frequency range").
    pub what: &'static str,
    /// Its start as given.
    pub start: f64,
    /// Its end as given.
    pub end: f64,
    /// Its number of values, for a grid (`None` for a range `(lo, hi)`).
    pub steps: Option<usize>,
    /// What is wrong with it.
    pub defect: RangeDefect,
}

impl std::fmt::Display for BadRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Self {
            what, start, end, ..
        } = self;
        write!(f, "the {what} from {start} to {end}")?;
        if let Some(steps) = self.steps {
            let plural = if steps == 1 { "" } else { "s" };
            write!(f, " in {steps} step{plural}")?;
        }
        match self.defect {
            RangeDefect::Empty if self.steps.is_some() => write!(
                f,
                " is empty: its ends are equal, so every step would compute the same point"
            ),
            RangeDefect::Empty => write!(f, " is empty: its ends are equal"),
            RangeDefect::Reversed => write!(
                f,
                " is reversed: it must rise, from its lower end to its higher ({start} > {end})"
            ),
            RangeDefect::SinglePoint => {
                write!(f, " has fewer than 2 values: give at least 2 steps")
            }
            RangeDefect::NotFinite => write!(f, " has an end that is not finite"),
            RangeDefect::NotPositive => {
                write!(f, " has an end that is not positive: both must be above 0")
            }
        }
    }
}

impl std::error::Error for BadRange {}

/// A grid or a range of frequencies is a setting.
impl From<BadRange> for Error {
    fn from(e: BadRange) -> Self {
        Error::Settings(e.into())
    }
}

impl Error {
    /// The range this error refuses, if it is one ([`SettingsError::Range`] or
    /// [`ContinuationError::Range`]): input to correct, not a computation that failed, so a
    /// front end can report it as a usage error.
    pub fn bad_range(&self) -> Option<&BadRange> {
        match self {
            Error::Settings(SettingsError::Range(r))
            | Error::Continuation(ContinuationError::Range(r)) => Some(r),
            _ => None,
        }
    }
}
