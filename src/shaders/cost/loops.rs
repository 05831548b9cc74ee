//! Trip counts of counted loops: the exit test, the counter's step, and every constant the
//! counter may hold when the loop starts, read from the IR. Anything the IR does not fix gives
//! no count (the loop is then reported as unbounded), never a guess.

use naga::{
    BinaryOperator, Block, Expression, Function, Handle, LocalVariable, Module, ScalarKind,
    Statement, TypeInner, UnaryOperator,
};

/// Loops running longer than this count as unbounded.
const MAX_TRIPS: u64 = 1 << 16;

/// Where a statement sits: the statements before it in its block, the loop whose body or
/// continuing block that is (if it is one), and the place of the block itself. What a loop
/// counter holds when its loop starts is read back along this path.
#[derive(Clone, Copy)]
pub(super) struct Place<'a> {
    /// The statements before it in its block.
    pub before: &'a [Statement],
    /// The body and continuing block of the loop whose block this is.
    pub in_loop: Option<(&'a Block, &'a Block)>,
    /// The place of the statement that holds the block (`None`: a function's body).
    pub outer: Option<&'a Place<'a>>,
}

/// A counted loop.
pub(super) struct Trips {
    /// Times the body runs.
    pub trips: u64,
    /// The exit test `if` at this index of the body: it and what precedes it run `trips + 1`
    /// times. `None`: the test is the continuing block's `break if`.
    pub test_at: Option<usize>,
}

/// The trip count of a loop at `place`, when the IR fixes it (the most it can be over every
/// start the counter may have).
pub(super) fn trip_count(
    module: &Module,
    f: &Function,
    place: &Place<'_>,
    body: &Block,
    continuing: &Block,
    break_if: Option<Handle<Expression>>,
) -> Option<Trips> {
    // The exit test: `if cond {} else { break; }` or `if cond { break; }` first in the body
    // (after the emits it reads), or `break if cond` at the end of the continuing block.
    let first = body.iter().position(|s| !matches!(s, Statement::Emit(_)));
    let top = first.and_then(|k| match &body[k] {
        Statement::If {
            condition,
            accept,
            reject,
        } => {
            let is_break = |b: &Block| matches!(&b[..], [Statement::Break]);
            if accept.is_empty() && is_break(reject) {
                Some((*condition, true, k))
            } else if reject.is_empty() && is_break(accept) {
                Some((*condition, false, k))
            } else {
                None
            }
        }
        _ => None,
    });
    let (mut test, mut stay_when, test_at) = match (top, break_if) {
        (Some((c, stay, k)), _) => (c, stay, Some(k)),
        (None, Some(c)) => (c, false, None),
        (None, None) => return None,
    };
    // `!(cond)`, as naga writes a GLSL `for`'s test.
    while let Expression::Unary {
        op: UnaryOperator::LogicalNot,
        expr,
    } = f.expressions[test]
    {
        test = expr;
        stay_when = !stay_when;
    }
    let (var, op, bound, load) = comparison(module, f, test)?;
    let ty = counter_type(module, f, var)?;
    // The body may not write the counter; the continuing block writes it once, at its top level,
    // as `counter = counter +/- constant`.
    let mut written = Vec::new();
    writes(f, body, var, &mut written);
    if !written.is_empty() {
        return None;
    }
    writes(f, continuing, var, &mut written);
    if written.len() != 1 {
        return None;
    }
    let (step_at, step) = continuing.iter().enumerate().find_map(|(i, s)| match s {
        Statement::Store { pointer, value } if local_root(f, *pointer) == Some(var) => {
            step(module, f, var, *value).map(|st| (i, st))
        }
        _ => None,
    })?;
    // Which value the test reads: at the top, the counter as the trip starts (read by the
    // emits before the test); in `break if`, the stepped one, or the one before the step when
    // it was read before the step.
    let tests_old = match test_at {
        Some(k) => {
            emitted_at(&body[..k], load)?;
            false
        }
        None => match emitted_at(continuing, load) {
            Some(i) => i < step_at,
            None => {
                emitted_at(body, load)?;
                true
            }
        },
    };
    let counter = Counter {
        step,
        op,
        bound,
        stay_when,
        test_first: test_at.is_some(),
        tests_old,
        ty,
    };
    let mut trips = 0;
    for start in start_values(module, f, var, place)? {
        trips = trips.max(counter.simulate(start)?);
    }
    Some(Trips { trips, test_at })
}

/// A loop's counter as the loop steps and tests it.
struct Counter {
    /// Added to the counter each trip.
    step: i128,
    /// The test's comparison: `counter op bound`.
    op: BinaryOperator,
    bound: i128,
    /// The test's value that keeps the loop going.
    stay_when: bool,
    /// Tested as a trip starts (a `for`'s or `while`'s test); else after the step (`break if`).
    test_first: bool,
    /// A test after the step reads the value from before it.
    tests_old: bool,
    ty: CounterType,
}

impl Counter {
    /// Runs the counter from `start`: the trips before the test leaves, or `None` past
    /// [`MAX_TRIPS`].
    fn simulate(&self, start: i128) -> Option<u64> {
        let ty = self.ty;
        let (mut i, bound, mut trips) = (ty.wrap(start), ty.wrap(self.bound), 0u64);
        loop {
            if self.test_first && holds(self.op, i, bound)? != self.stay_when {
                return Some(trips);
            }
            trips += 1;
            if trips > MAX_TRIPS {
                return None;
            }
            let old = i;
            i = ty.wrap(i + self.step);
            let tested = if self.tests_old { old } else { i };
            if !self.test_first && holds(self.op, tested, bound)? != self.stay_when {
                return Some(trips);
            }
        }
    }
}

/// An integer counter's width and signedness: its arithmetic wraps.
#[derive(Clone, Copy)]
struct CounterType {
    bits: u32,
    signed: bool,
}

impl CounterType {
    fn wrap(self, v: i128) -> i128 {
        let m = 1i128 << self.bits;
        let u = v.rem_euclid(m);
        if self.signed && u >= m / 2 { u - m } else { u }
    }
}

fn counter_type(module: &Module, f: &Function, var: Handle<LocalVariable>) -> Option<CounterType> {
    match module.types[f.local_variables[var].ty].inner {
        TypeInner::Scalar(s) if matches!(s.kind, ScalarKind::Sint | ScalarKind::Uint) => {
            Some(CounterType {
                bits: u32::from(s.width) * 8,
                signed: s.kind == ScalarKind::Sint,
            })
        }
        _ => None,
    }
}

/// Every constant `var` may hold at `place`: the last store before it on the path from the
/// function's start, what stores under branches on the way may have set, what an enclosing
/// loop stores (its earlier trips ran before), else the initializer (or zero). `None` when one
/// of them is not a constant, or a call is handed a pointer to the counter.
fn start_values(
    module: &Module,
    f: &Function,
    var: Handle<LocalVariable>,
    place: &Place<'_>,
) -> Option<Vec<i128>> {
    let mut values = Vec::new();
    let mut at = Some(place);
    while let Some(p) = at {
        for s in p.before.iter().rev() {
            if let Statement::Store { pointer, value } = s
                && matches!(f.expressions[*pointer], Expression::LocalVariable(v) if v == var)
            {
                values.push(i128::from(constant(module, &f.expressions, *value)?));
                return Some(values);
            }
            let mut written = Vec::new();
            writes(f, std::slice::from_ref(s), var, &mut written);
            constants_of(module, f, &written, &mut values)?;
        }
        if let Some((body, continuing)) = p.in_loop {
            let mut written = Vec::new();
            writes(f, body, var, &mut written);
            writes(f, continuing, var, &mut written);
            constants_of(module, f, &written, &mut values)?;
        }
        at = p.outer;
    }
    let init = match f.local_variables[var].init {
        Some(init) => constant(module, &f.expressions, init)?,
        None => 0,
    };
    values.push(i128::from(init));
    Some(values)
}

/// The constants `written` stores, into `values`; `None` when one is not a constant.
fn constants_of(
    module: &Module,
    f: &Function,
    written: &[Option<Handle<Expression>>],
    values: &mut Vec<i128>,
) -> Option<()> {
    for w in written {
        values.push(i128::from(constant(module, &f.expressions, (*w)?)?));
    }
    Some(())
}

/// Every write to `var` in `stmts`, nested ones too: the stored value, or `None` for a write
/// the IR does not show (a call handed a pointer to the counter).
fn writes(
    f: &Function,
    stmts: &[Statement],
    var: Handle<LocalVariable>,
    out: &mut Vec<Option<Handle<Expression>>>,
) {
    for s in stmts {
        match s {
            Statement::Store { pointer, value } if local_root(f, *pointer) == Some(var) => {
                out.push(Some(*value));
            }
            Statement::Call { arguments, .. }
                if arguments.iter().any(|a| local_root(f, *a) == Some(var)) =>
            {
                out.push(None);
            }
            Statement::Block(b) => writes(f, b, var, out),
            Statement::If { accept, reject, .. } => {
                writes(f, accept, var, out);
                writes(f, reject, var, out);
            }
            Statement::Switch { cases, .. } => {
                for c in cases {
                    writes(f, &c.body, var, out);
                }
            }
            Statement::Loop {
                body, continuing, ..
            } => {
                writes(f, body, var, out);
                writes(f, continuing, var, out);
            }
            _ => {}
        }
    }
}

/// The index in `stmts` of the `Emit` that evaluates `h`.
fn emitted_at(stmts: &[Statement], h: Handle<Expression>) -> Option<usize> {
    stmts
        .iter()
        .position(|s| matches!(s, Statement::Emit(r) if r.clone().any(|e| e == h)))
}

/// The local variable a pointer points into (through accesses).
fn local_root(f: &Function, mut h: Handle<Expression>) -> Option<Handle<LocalVariable>> {
    loop {
        match &f.expressions[h] {
            Expression::LocalVariable(v) => return Some(*v),
            Expression::Access { base, .. } | Expression::AccessIndex { base, .. } => h = *base,
            _ => return None,
        }
    }
}

/// The step of `counter = counter + c` (or `c + counter`) or `counter - c`.
fn step(
    module: &Module,
    f: &Function,
    var: Handle<LocalVariable>,
    value: Handle<Expression>,
) -> Option<i128> {
    let Expression::Binary { op, left, right } = f.expressions[value] else {
        return None;
    };
    let c = |h| constant(module, &f.expressions, h).map(i128::from);
    match op {
        BinaryOperator::Add if loaded_local(f, left) == Some(var) => c(right),
        BinaryOperator::Add if loaded_local(f, right) == Some(var) => c(left),
        BinaryOperator::Subtract if loaded_local(f, left) == Some(var) => c(right).map(|s| -s),
        _ => None,
    }
}

/// An integer the IR fixes: a literal, a constant, a zero value.
fn constant(
    module: &Module,
    exprs: &naga::Arena<Expression>,
    h: Handle<Expression>,
) -> Option<i64> {
    match &exprs[h] {
        Expression::Literal(l) => literal(*l),
        Expression::Constant(c) => {
            let init = module.constants[*c].init;
            constant(module, &module.global_expressions, init)
        }
        Expression::ZeroValue(_) => Some(0),
        _ => None,
    }
}

fn literal(l: naga::Literal) -> Option<i64> {
    match l {
        naga::Literal::U32(v) => Some(i64::from(v)),
        naga::Literal::I32(v) => Some(i64::from(v)),
        naga::Literal::U64(v) => i64::try_from(v).ok(),
        naga::Literal::I64(v) | naga::Literal::AbstractInt(v) => Some(v),
        _ => None,
    }
}

/// The local variable a `Load` reads, if it is one.
fn loaded_local(f: &Function, h: Handle<Expression>) -> Option<Handle<LocalVariable>> {
    match &f.expressions[h] {
        Expression::Load { pointer } => match &f.expressions[*pointer] {
            Expression::LocalVariable(v) => Some(*v),
            _ => None,
        },
        _ => None,
    }
}

/// A comparison `counter op bound` with a constant bound: (counter, op, bound, the counter's
/// load), the counter on the left (a bound on the left is turned around).
fn comparison(
    module: &Module,
    f: &Function,
    h: Handle<Expression>,
) -> Option<(
    Handle<LocalVariable>,
    BinaryOperator,
    i128,
    Handle<Expression>,
)> {
    use BinaryOperator as B;
    let Expression::Binary { op, left, right } = f.expressions[h] else {
        return None;
    };
    if let (Some(v), Some(b)) = (
        loaded_local(f, left),
        constant(module, &f.expressions, right),
    ) {
        return Some((v, op, i128::from(b), left));
    }
    let (v, b) = (
        loaded_local(f, right)?,
        constant(module, &f.expressions, left)?,
    );
    let flipped = match op {
        B::Less => B::Greater,
        B::LessEqual => B::GreaterEqual,
        B::Greater => B::Less,
        B::GreaterEqual => B::LessEqual,
        other => other,
    };
    Some((v, flipped, i128::from(b), right))
}

fn holds(op: BinaryOperator, a: i128, b: i128) -> Option<bool> {
    use BinaryOperator as B;
    Some(match op {
        B::Less => a < b,
        B::LessEqual => a <= b,
        B::Greater => a > b,
        B::GreaterEqual => a >= b,
        B::NotEqual => a != b,
        B::Equal => a == b,
        _ => return None,
    })
}
