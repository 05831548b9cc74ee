//! What a shader costs, counted from its naga IR: per entry point, the texture loads, samples,
//! gathers and storage reads it makes and its ALU operations, for one invocation. These counts
//! hold on any GPU (before caches), where timings on one machine do not, so a CI can hold a
//! shader to a budget (`lodkit check --stats --budget FILE`).
//!
//! Calls are inlined by walking the call graph. A loop whose trip count the IR fixes (a counter
//! from a constant, compared with a constant, stepped by a constant, as `for (var i = 0u; i < 4u;
//! i++)` gives) multiplies its body; any other loop counts once and is reported in
//! [`EntryCost::unknown_loops`]. What runs under an `if` or `switch` is counted apart as
//! `conditional`: the most that any one path through the branches adds (per count, so a sound
//! upper bound), on top of the `always` part, what runs outside any branch. (What follows an
//! early `return` inside a branch still counts as `always`: the main path.)

use std::collections::BTreeMap;

use naga::{Block, Expression, Function, Handle, Module, Statement};
use serde::Serialize;

/// What kind of memory read a fetch is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FetchKind {
    /// `textureLoad`: one texel.
    TextureLoad,
    /// `textureSample*`: one texel, or four with a linear filter (the sampler decides).
    Sample,
    /// `textureGather*`: four texels.
    Gather,
    /// A load from a `var<storage>` buffer.
    StorageRead,
}

/// Counts of one invocation of an entry point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// `textureLoad` calls.
    pub texture_loads: u64,
    /// `textureSample*` calls.
    pub samples: u64,
    /// `textureGather*` calls.
    pub gathers: u64,
    /// Loads from storage buffers.
    pub storage_reads: u64,
    /// Arithmetic, logic, comparison, conversion, selection and built-in math operations.
    pub alu: u64,
}

impl Counts {
    /// All fetches: texture loads, samples, gathers and storage reads.
    pub fn fetches(&self) -> u64 {
        self.texture_loads + self.samples + self.gathers + self.storage_reads
    }

    fn add_fetch(&mut self, kind: FetchKind, n: u64) {
        match kind {
            FetchKind::TextureLoad => self.texture_loads += n,
            FetchKind::Sample => self.samples += n,
            FetchKind::Gather => self.gathers += n,
            FetchKind::StorageRead => self.storage_reads += n,
        }
    }

    fn plus(self, o: Self) -> Self {
        Self {
            texture_loads: self.texture_loads + o.texture_loads,
            samples: self.samples + o.samples,
            gathers: self.gathers + o.gathers,
            storage_reads: self.storage_reads + o.storage_reads,
            alu: self.alu + o.alu,
        }
    }

    fn max(self, o: Self) -> Self {
        Self {
            texture_loads: self.texture_loads.max(o.texture_loads),
            samples: self.samples.max(o.samples),
            gathers: self.gathers.max(o.gathers),
            storage_reads: self.storage_reads.max(o.storage_reads),
            alu: self.alu.max(o.alu),
        }
    }
}

/// The fetches of one kind from one resource (a global variable: texture or storage buffer).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ResourceFetches {
    /// The global variable's name (`?` when it has none).
    pub resource: String,
    /// Its `@group` and `@binding`.
    pub binding: Option<(u32, u32)>,
    /// Load, sample, gather or storage read.
    pub kind: FetchKind,
    /// Fetches every invocation makes.
    pub always: u64,
    /// Fetches under branches, at most (on the costliest path).
    pub conditional: u64,
}

/// The cost of one invocation of an entry point.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct EntryCost {
    /// The entry point's name.
    pub name: String,
    /// `vertex`, `fragment`, `compute`, ...
    pub stage: String,
    /// What runs outside any branch: the main path.
    pub always: Counts,
    /// What branches add at most, on top of `always`.
    pub conditional: Counts,
    /// Per resource and kind of fetch, in binding order.
    pub resources: Vec<ResourceFetches>,
    /// Loops whose trip count the IR does not fix: their bodies are counted once.
    pub unknown_loops: u32,
}

impl EntryCost {
    /// The most an invocation can execute: `always` plus `conditional`.
    pub fn worst(&self) -> Counts {
        self.always.plus(self.conditional)
    }
}

/// The cost of every entry point of `module`, in the module's order.
pub fn entry_point_costs(module: &Module) -> Vec<EntryCost> {
    module
        .entry_points
        .iter()
        .map(|ep| {
            let mut walker = Walker {
                module,
                unknown_loops: 0,
            };
            let tally = walker.block(&ep.function, &ep.function.body, &[], 0);
            let mut resources: Vec<ResourceFetches> = tally
                .fetches
                .iter()
                .map(|(&(global, kind), &(always, conditional))| {
                    let var = &module.global_variables[global];
                    ResourceFetches {
                        resource: var.name.clone().unwrap_or_else(|| "?".to_owned()),
                        binding: var.binding.as_ref().map(|b| (b.group, b.binding)),
                        kind,
                        always,
                        conditional,
                    }
                })
                .collect();
            resources.sort_by(|a, b| {
                (a.binding, &a.resource, a.kind).cmp(&(b.binding, &b.resource, b.kind))
            });
            EntryCost {
                name: ep.name.clone(),
                stage: format!("{:?}", ep.stage).to_lowercase(),
                always: tally.always,
                conditional: tally.conditional,
                resources,
                unknown_loops: walker.unknown_loops,
            }
        })
        .collect()
}

/// Counts of a block: what always runs, what its branches add at most, and per-resource
/// fetches as (always, conditional).
#[derive(Clone, Default)]
struct Tally {
    always: Counts,
    conditional: Counts,
    fetches: BTreeMap<(Handle<naga::GlobalVariable>, FetchKind), (u64, u64)>,
}

impl Tally {
    fn add(&mut self, o: &Tally) {
        self.always = self.always.plus(o.always);
        self.conditional = self.conditional.plus(o.conditional);
        for (k, (a, c)) in &o.fetches {
            let e = self.fetches.entry(*k).or_default();
            e.0 += a;
            e.1 += c;
        }
    }

    fn times(mut self, n: u64) -> Tally {
        let scale = |c: Counts| Counts {
            texture_loads: c.texture_loads * n,
            samples: c.samples * n,
            gathers: c.gathers * n,
            storage_reads: c.storage_reads * n,
            alu: c.alu * n,
        };
        self.always = scale(self.always);
        self.conditional = scale(self.conditional);
        for v in self.fetches.values_mut() {
            *v = (v.0 * n, v.1 * n);
        }
        self
    }

    /// One of `branches` runs: everything in them becomes conditional, at most the costliest.
    fn branch(&mut self, branches: &[Tally]) {
        let mut worst = Counts::default();
        let mut fetches: BTreeMap<_, u64> = BTreeMap::new();
        for b in branches {
            worst = worst.max(b.always.plus(b.conditional));
            for (k, (a, c)) in &b.fetches {
                let e = fetches.entry(*k).or_default();
                *e = (*e).max(a + c);
            }
        }
        self.conditional = self.conditional.plus(worst);
        for (k, n) in fetches {
            self.fetches.entry(k).or_default().1 += n;
        }
    }
}

/// Calls deeper than this are not followed (WGSL has no recursion; this bounds bad IR).
const MAX_CALL_DEPTH: usize = 64;
/// Loops running longer than this count as unknown.
const MAX_TRIPS: u64 = 1 << 16;

struct Walker<'a> {
    module: &'a Module,
    unknown_loops: u32,
}

/// For each argument of the function being walked, the global variable it passes on (a texture
/// or a storage pointer handed down by the caller).
type Args = [Option<Handle<naga::GlobalVariable>>];

impl Walker<'_> {
    fn block(&mut self, f: &Function, block: &Block, args: &Args, depth: usize) -> Tally {
        let mut t = Tally::default();
        for (i, stmt) in block.iter().enumerate() {
            match stmt {
                Statement::Emit(range) => {
                    for h in range.clone() {
                        self.expression(f, h, args, &mut t);
                    }
                }
                Statement::Block(b) => t.add(&self.block(f, b, args, depth)),
                Statement::If { accept, reject, .. } => {
                    let branches = [
                        self.block(f, accept, args, depth),
                        self.block(f, reject, args, depth),
                    ];
                    t.branch(&branches);
                }
                Statement::Switch { cases, .. } => {
                    let branches: Vec<Tally> = cases
                        .iter()
                        .map(|c| self.block(f, &c.body, args, depth))
                        .collect();
                    t.branch(&branches);
                }
                Statement::Loop {
                    body,
                    continuing,
                    break_if,
                } => {
                    let mut once = self.block(f, body, args, depth);
                    once.add(&self.block(f, continuing, args, depth));
                    let trips =
                        trip_count(self.module, f, &block[..i], body, continuing, *break_if);
                    if trips.is_none() {
                        self.unknown_loops += 1;
                    }
                    t.add(&once.times(trips.unwrap_or(1)));
                }
                Statement::Call {
                    function,
                    arguments,
                    ..
                } if depth < MAX_CALL_DEPTH => {
                    let callee = &self.module.functions[*function];
                    let passed: Vec<_> =
                        arguments.iter().map(|a| global_root(f, *a, args)).collect();
                    t.add(&self.block(callee, &callee.body, &passed, depth + 1));
                }
                Statement::Atomic { pointer, .. } => {
                    if let Some(g) = storage_root(self.module, f, *pointer, args) {
                        fetch(&mut t, Some(g), FetchKind::StorageRead);
                    }
                }
                _ => {}
            }
        }
        t
    }

    fn expression(&mut self, f: &Function, h: Handle<Expression>, args: &Args, t: &mut Tally) {
        match &f.expressions[h] {
            Expression::ImageSample { image, gather, .. } => {
                let kind = if gather.is_some() {
                    FetchKind::Gather
                } else {
                    FetchKind::Sample
                };
                fetch(t, global_root(f, *image, args), kind);
            }
            Expression::ImageLoad { image, .. } => {
                fetch(t, global_root(f, *image, args), FetchKind::TextureLoad);
            }
            Expression::Load { pointer } => {
                if let Some(g) = storage_root(self.module, f, *pointer, args) {
                    fetch(t, Some(g), FetchKind::StorageRead);
                }
            }
            Expression::Unary { .. }
            | Expression::Binary { .. }
            | Expression::Select { .. }
            | Expression::Derivative { .. }
            | Expression::Relational { .. }
            | Expression::Math { .. }
            | Expression::As { .. } => t.always.alu += 1,
            _ => {}
        }
    }
}

/// One fetch; by resource too when the texture or buffer it reads is known (a texture that
/// reaches a function some other way than as a global or an argument counts in the totals only).
fn fetch(t: &mut Tally, g: Option<Handle<naga::GlobalVariable>>, kind: FetchKind) {
    t.always.add_fetch(kind, 1);
    if let Some(g) = g {
        t.fetches.entry((g, kind)).or_default().0 += 1;
    }
}

/// The global variable an image or pointer expression reads from (through binding-array and
/// struct accesses, and arguments the caller passed).
fn global_root(
    f: &Function,
    mut h: Handle<Expression>,
    args: &Args,
) -> Option<Handle<naga::GlobalVariable>> {
    loop {
        match &f.expressions[h] {
            Expression::GlobalVariable(g) => return Some(*g),
            Expression::FunctionArgument(i) => return args.get(*i as usize).copied().flatten(),
            Expression::Access { base, .. } | Expression::AccessIndex { base, .. } => h = *base,
            _ => return None,
        }
    }
}

fn storage_root(
    module: &Module,
    f: &Function,
    pointer: Handle<Expression>,
    args: &Args,
) -> Option<Handle<naga::GlobalVariable>> {
    let g = global_root(f, pointer, args)?;
    matches!(
        module.global_variables[g].space,
        naga::AddressSpace::Storage { .. }
    )
    .then_some(g)
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
fn loaded_local(f: &Function, h: Handle<Expression>) -> Option<Handle<naga::LocalVariable>> {
    match &f.expressions[h] {
        Expression::Load { pointer } => match &f.expressions[*pointer] {
            Expression::LocalVariable(v) => Some(*v),
            _ => None,
        },
        _ => None,
    }
}

/// A comparison `counter op bound` with a constant bound: (counter, op, bound), the counter on
/// the left (a bound on the left is turned around).
fn comparison(
    module: &Module,
    f: &Function,
    h: Handle<Expression>,
) -> Option<(Handle<naga::LocalVariable>, naga::BinaryOperator, i64)> {
    use naga::BinaryOperator as B;
    let Expression::Binary { op, left, right } = &f.expressions[h] else {
        return None;
    };
    if let (Some(v), Some(b)) = (
        loaded_local(f, *left),
        constant(module, &f.expressions, *right),
    ) {
        return Some((v, *op, b));
    }
    let (v, b) = (
        loaded_local(f, *right)?,
        constant(module, &f.expressions, *left)?,
    );
    let flipped = match op {
        B::Less => B::Greater,
        B::LessEqual => B::GreaterEqual,
        B::Greater => B::Less,
        B::GreaterEqual => B::LessEqual,
        other => *other,
    };
    Some((v, flipped, b))
}

fn holds(op: naga::BinaryOperator, a: i64, b: i64) -> Option<bool> {
    use naga::BinaryOperator as B;
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

/// The trip count of a counted loop, when the IR fixes it. `before` is what precedes the loop
/// in its block (where the counter is set).
fn trip_count(
    module: &Module,
    f: &Function,
    before: &[Statement],
    body: &Block,
    continuing: &Block,
    break_if: Option<Handle<Expression>>,
) -> Option<u64> {
    // The exit test: `if cond {} else { break; }` (or `if cond { break; }`) first in the body,
    // or `break if cond` at the end of the continuing block.
    let (test, stay_when) = body
        .iter()
        .find_map(|s| match s {
            Statement::Emit(_) => None,
            Statement::If {
                condition,
                accept,
                reject,
            } => {
                let is_break =
                    |b: &Block| b.len() == 1 && matches!(b.iter().next(), Some(Statement::Break));
                if accept.is_empty() && is_break(reject) {
                    Some(Some((*condition, true)))
                } else if reject.is_empty() && is_break(accept) {
                    Some(Some((*condition, false)))
                } else {
                    Some(None)
                }
            }
            _ => Some(None),
        })
        .flatten()
        .or_else(|| break_if.map(|c| (c, false)))?;
    let (var, op, bound) = comparison(module, f, test)?;
    // The step: `counter = counter +/- constant` in the continuing block.
    let step = continuing.iter().find_map(|s| match s {
        Statement::Store { pointer, value }
            if matches!(f.expressions[*pointer], Expression::LocalVariable(v) if v == var) =>
        {
            match &f.expressions[*value] {
                Expression::Binary {
                    op: naga::BinaryOperator::Add,
                    left,
                    right,
                } if loaded_local(f, *left) == Some(var) => constant(module, &f.expressions, *right),
                Expression::Binary {
                    op: naga::BinaryOperator::Subtract,
                    left,
                    right,
                } if loaded_local(f, *left) == Some(var) => {
                    constant(module, &f.expressions, *right).map(|s| -s)
                }
                _ => None,
            }
        }
        _ => None,
    })?;
    // The start: the last store before the loop, else the variable's initializer, else zero.
    let start = before
        .iter()
        .rev()
        .find_map(|s| match s {
            Statement::Store { pointer, value }
                if matches!(f.expressions[*pointer], Expression::LocalVariable(v) if v == var) =>
            {
                Some(constant(module, &f.expressions, *value))
            }
            _ => None,
        })
        .unwrap_or_else(|| match f.local_variables[var].init {
            Some(init) => constant(module, &f.expressions, init),
            None => Some(0),
        })?;
    // A body that also stores to the counter is not a counted loop.
    if stores_to(f, body, var) {
        return None;
    }
    let (mut i, mut trips) = (start, 0u64);
    // With `break if`, the body runs before the first test.
    if Some(test) == break_if {
        loop {
            trips += 1;
            i += step;
            if holds(op, i, bound)? != stay_when || trips > MAX_TRIPS {
                break;
            }
        }
    } else {
        while holds(op, i, bound)? == stay_when {
            trips += 1;
            i += step;
            if trips > MAX_TRIPS {
                return None;
            }
        }
    }
    (trips <= MAX_TRIPS).then_some(trips)
}

fn stores_to(f: &Function, block: &Block, var: Handle<naga::LocalVariable>) -> bool {
    block.iter().any(|s| match s {
        Statement::Store { pointer, .. } => {
            matches!(f.expressions[*pointer], Expression::LocalVariable(v) if v == var)
        }
        Statement::Block(b) => stores_to(f, b, var),
        Statement::If { accept, reject, .. } => {
            stores_to(f, accept, var) || stores_to(f, reject, var)
        }
        Statement::Switch { cases, .. } => cases.iter().any(|c| stores_to(f, &c.body, var)),
        Statement::Loop {
            body, continuing, ..
        } => stores_to(f, body, var) || stores_to(f, continuing, var),
        _ => false,
    })
}
