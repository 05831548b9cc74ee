//! What a shader costs, counted from its naga IR: per entry point, the texture loads, samples,
//! gathers and storage reads it makes and its ALU operations, for one invocation. These counts
//! hold on any GPU (before caches), where timings on one machine do not, so a CI can hold a
//! shader to a budget (`lodkit check --stats --budget FILE`).
//!
//! The counts never undercount: where the IR leaves a choice they take the costliest one, and a
//! loop they cannot bound is reported.
//!
//! - Calls are inlined by walking the call graph.
//! - A loop whose trip count the IR fixes multiplies its body: a counter compared with a
//!   constant and stepped by a constant, whatever constant it may hold when the loop starts (set
//!   before the loop, in an enclosing block, or under a branch: the start that gives the most
//!   trips counts). `for (var i = 0u; i < 4u; i++)`, a GLSL `for` (which naga lowers to
//!   `loop { if (!(cond)) { break; } ... }`), the same written by hand, and
//!   `loop { ... continuing { k += 1u; break if k >= 3u; } }` are counted. Counters wrap as
//!   their type does (a `u32` counting down to `i >= 0u` never stops). The exit test at the top
//!   of a loop runs once more than its body.
//! - Any other loop counts once and is reported in [`EntryCost::unknown_loops`] (and, by the
//!   function it is in, [`EntryCost::unknown_loops_in`]): the counts are then no upper bound.
//! - What runs under an `if` or `switch` is counted apart as `conditional`: the most that any
//!   one path through the branches adds (per count, so a sound upper bound), on top of the
//!   `always` part, what runs outside any branch. A `switch` case that falls through (GLSL)
//!   pays for the cases it falls into. (What follows an early `return` inside a branch still
//!   counts as `always`: the main path.)

use std::collections::BTreeMap;

use naga::{Block, Expression, Function, Handle, Module, Statement};
use serde::Serialize;

mod loops;

use loops::Place;

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
    /// Loops the counter could not bound (the IR does not fix their trip count): their bodies
    /// are counted once, so the counts are then no upper bound. A loop in a function called
    /// twice counts twice.
    pub unknown_loops: u32,
    /// The function each of those loops is in (the entry point's own name for its body), in
    /// the order they were met; as long as `unknown_loops`.
    pub unknown_loops_in: Vec<String>,
}

impl EntryCost {
    /// The most an invocation can execute: `always` plus `conditional`. With
    /// [`unknown_loops`](Self::unknown_loops) above zero, an invocation may execute more.
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
                unknown_loops_in: Vec::new(),
            };
            let entry = Walked {
                f: &ep.function,
                name: &ep.name,
                args: &[],
                depth: 0,
            };
            let tally = walker.block(entry, &ep.function.body, None);
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
                unknown_loops: u32::try_from(walker.unknown_loops_in.len()).unwrap_or(u32::MAX),
                unknown_loops_in: walker.unknown_loops_in,
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

struct Walker<'a> {
    module: &'a Module,
    unknown_loops_in: Vec<String>,
}

/// For each argument of the function being walked, the global variable it passes on (a texture
/// or a storage pointer handed down by the caller).
type Args = [Option<Handle<naga::GlobalVariable>>];

/// A function as the walk reaches it.
#[derive(Clone, Copy)]
struct Walked<'a> {
    f: &'a Function,
    /// Its name (an entry point's, or the function's).
    name: &'a str,
    /// What its arguments pass on.
    args: &'a Args,
    /// Calls from the entry point down to it.
    depth: usize,
}

impl Walker<'_> {
    /// The tally of `stmts`, statements of `fun`; `outer` is where the block sits (`None` for a
    /// function's body), for what a loop counter holds when its loop starts.
    fn block(&mut self, fun: Walked<'_>, stmts: &[Statement], outer: Option<&Place<'_>>) -> Tally {
        self.block_in(fun, stmts, outer, None)
    }

    /// [`block`](Self::block) for a loop's body or continuing block (`in_loop`: the loop's
    /// body and continuing block).
    fn block_in(
        &mut self,
        fun: Walked<'_>,
        stmts: &[Statement],
        outer: Option<&Place<'_>>,
        in_loop: Option<(&Block, &Block)>,
    ) -> Tally {
        let Walked {
            f,
            name,
            args,
            depth,
        } = fun;
        let mut t = Tally::default();
        for (i, stmt) in stmts.iter().enumerate() {
            let here = Place {
                before: &stmts[..i],
                in_loop,
                outer,
            };
            let inner = Some(&here);
            match stmt {
                Statement::Emit(range) => {
                    for h in range.clone() {
                        self.expression(f, h, args, &mut t);
                    }
                }
                Statement::Block(b) => t.add(&self.block(fun, b, inner)),
                Statement::If { accept, reject, .. } => {
                    let branches = [
                        self.block(fun, accept, inner),
                        self.block(fun, reject, inner),
                    ];
                    t.branch(&branches);
                }
                Statement::Switch { cases, .. } => {
                    let bodies: Vec<Tally> = cases
                        .iter()
                        .map(|c| self.block(fun, &c.body, inner))
                        .collect();
                    // A path starts at a case and runs on through the cases it falls into.
                    let mut paths = bodies.clone();
                    for j in (0..cases.len().saturating_sub(1)).rev() {
                        if cases[j].fall_through {
                            let next = paths[j + 1].clone();
                            paths[j].add(&next);
                        }
                    }
                    t.branch(&paths);
                }
                Statement::Loop {
                    body,
                    continuing,
                    break_if,
                } => {
                    let inside = Some((body, continuing));
                    let walk =
                        |s: &mut Self, part: &[Statement]| s.block_in(fun, part, inner, inside);
                    match loops::trip_count(self.module, f, &here, body, continuing, *break_if) {
                        Some(loops::Trips {
                            trips,
                            test_at: Some(k),
                        }) => {
                            // The exit test at the top runs once more than the rest.
                            let head = walk(self, &body[..=k]);
                            let mut rest = walk(self, &body[k + 1..]);
                            rest.add(&walk(self, continuing));
                            t.add(&head.times(trips + 1));
                            t.add(&rest.times(trips));
                        }
                        Some(loops::Trips {
                            trips,
                            test_at: None,
                        }) => {
                            let mut once = walk(self, body);
                            once.add(&walk(self, continuing));
                            t.add(&once.times(trips));
                        }
                        None => {
                            let mut once = walk(self, body);
                            once.add(&walk(self, continuing));
                            self.unknown_loops_in.push(name.to_owned());
                            t.add(&once);
                        }
                    }
                }
                Statement::Call {
                    function,
                    arguments,
                    ..
                } if depth < MAX_CALL_DEPTH => {
                    let callee = &self.module.functions[*function];
                    let passed: Vec<_> =
                        arguments.iter().map(|a| global_root(f, *a, args)).collect();
                    let callee_name = callee.name.as_deref().unwrap_or("?");
                    let called = Walked {
                        f: callee,
                        name: callee_name,
                        args: &passed,
                        depth: depth + 1,
                    };
                    t.add(&self.block(called, &callee.body, None));
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
