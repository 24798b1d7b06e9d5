#![deny(missing_docs)]
//! Coverage of WGSL (SPEC 20): which statements and branch arms of a
//! kernel its cases execute.
//!
//! [`instrument`] rewrites a validated naga module so that every
//! straight-line run of statements (a *segment*: statements that execute
//! the same number of times, ended by any statement that branches, loops
//! or leaves) first adds one to its own counter, an `atomicAdd` on
//! `vista_coverage: array<atomic<u32>>` at a group the pass does not bind.
//! Each branch arm (an `if`'s accept and reject blocks, a `switch`'s
//! cases, a loop's body; `&&` and `||` are `if`s in naga's IR) starts a
//! segment of its own, so arms are counted even when empty. Vertex entries
//! and the functions they reach are counted only where the device lets
//! the vertex stage write storage (wgpu's `VERTEX_WRITABLE_STORAGE`; not
//! WebGPU's core); elsewhere they are left as they are: *not measured*,
//! never *unexecuted*.
//!
//! [`Counts`] maps the counters back to lines through a caller's
//! span-to-place function (the composed source's files and lines) and
//! writes LCOV (`lcov.info`: `DA` per line, `BRDA` per arm).
//!
//! Not for: binding the buffer or reading it back (the engine), or which
//! cases run (the caller).

mod lcov;

pub use lcov::{Counts, Place};

use naga::{
    AddressSpace, AtomicFunction, Block, Expression, Function, Handle, Literal, Module, ResourceBinding, Scalar,
    ShaderStage, Span, Statement, StorageAccess, Type, TypeInner,
};

/// The counter buffer's WGSL variable.
pub const VAR: &str = "vista_coverage";

/// Which arm of a branch a counter counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arm {
    /// The span of the `if`, `switch` or `loop` statement.
    pub at: Span,
    /// 0: the accept block (a case's index, a loop's body); 1: reject.
    pub branch: u32,
}

/// One counter: the statements it counts, and the arm it starts, if any.
#[derive(Debug, Clone, PartialEq)]
pub struct Counter {
    /// The spans of the statements of its segment (possibly none: an
    /// empty arm).
    pub spans: Vec<Span>,
    /// The branch arm whose start it is.
    pub arm: Option<Arm>,
    /// The function it is in (an entry point's name for its body).
    pub function: String,
    /// A counter with no word of its own: counter `.0`'s value less counter
    /// `.1`'s (a select's false arm: its statement's runs less its true
    /// arm's), one atomic fewer where every one costs llvmpipe compile time.
    pub derived: Option<(usize, usize)>,
}

/// A module with its counters.
#[derive(Debug, Clone)]
pub struct Instrumented {
    /// The instrumented module (validate it as any module).
    pub module: Module,
    /// Counter i is element i of [`VAR`].
    pub counters: Vec<Counter>,
    /// Where [`VAR`] is bound.
    pub binding: ResourceBinding,
    /// Functions left uninstrumented (a vertex entry reaches them, and the
    /// vertex stage may not write storage): their lines are not measured.
    pub not_measured: Vec<String>,
}

/// The module with a counter per segment and per arm, its buffer at
/// `group`, binding 0 (a group no pass of the module's uses); `vertex`:
/// whether vertex entries may write it (they are counted then).
pub fn instrument(module: &Module, group: u32, vertex: bool) -> Instrumented {
    let mut m = module.clone();
    let atomic = m.types.insert(Type { name: None, inner: TypeInner::Atomic(Scalar::U32) }, Span::UNDEFINED);
    let array = m.types.insert(
        Type { name: None, inner: TypeInner::Array { base: atomic, size: naga::ArraySize::Dynamic, stride: 4 } },
        Span::UNDEFINED,
    );
    let binding = ResourceBinding { group, binding: 0 };
    let global = m.global_variables.append(
        naga::GlobalVariable {
            name: Some(VAR.to_string()),
            space: AddressSpace::Storage { access: StorageAccess::LOAD | StorageAccess::STORE },
            binding: Some(binding),
            ty: array,
            init: None,
            memory_decorations: naga::MemoryDecorations::empty(),
        },
        Span::UNDEFINED,
    );
    let uncounted = if vertex { Vec::new() } else { reached_from_vertex(&m) };
    // Expression types, to tell a scalar `select` (whose arms are counted)
    // from a component-wise one; a module that does not validate gets none.
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(module)
        .ok();
    let mut counters = Vec::new();
    let mut not_measured = Vec::new();
    let handles: Vec<Handle<Function>> = m.functions.iter().map(|(h, _)| h).collect();
    for h in handles {
        let name = m.functions[h].name.clone().unwrap_or_default();
        if uncounted.contains(&h) {
            not_measured.push(name);
            continue;
        }
        let scalar = scalar_selects(&m.functions[h], &m.types, info.as_ref().map(|i| &i[h]));
        instrument_function(&mut m.functions[h], global, &name, &mut counters, &scalar);
    }
    for (i, ep) in m.entry_points.iter_mut().enumerate() {
        if ep.stage == ShaderStage::Vertex && !vertex {
            not_measured.push(ep.name.clone());
            continue;
        }
        let name = ep.name.clone();
        let scalar = scalar_selects(&ep.function, &m.types, info.as_ref().map(|info| info.get_entry_point(i)));
        instrument_function(&mut ep.function, global, &name, &mut counters, &scalar);
    }
    Instrumented { module: m, counters, binding, not_measured }
}

/// Whether control may leave `s` other than to the statement after it: a
/// return or discard anywhere inside; a break or continue not inside a
/// loop of its own (a switch's break only leaves the switch). A segment
/// goes on past a statement that does not escape.
fn escapes(s: &Statement) -> bool {
    fn inside(block: &Block, in_loop: bool, in_switch: bool) -> bool {
        block.iter().any(|s| match s {
            Statement::Return { .. } | Statement::Kill => true,
            Statement::Break => !in_loop && !in_switch,
            Statement::Continue => !in_loop,
            Statement::Block(b) => inside(b, in_loop, in_switch),
            Statement::If { accept, reject, .. } => {
                inside(accept, in_loop, in_switch) || inside(reject, in_loop, in_switch)
            }
            Statement::Switch { cases, .. } => cases.iter().any(|c| inside(&c.body, in_loop, true)),
            Statement::Loop { body, continuing, .. } => inside(body, true, false) || inside(continuing, true, false),
            _ => false,
        })
    }
    match s {
        Statement::Return { .. } | Statement::Kill | Statement::Break | Statement::Continue => true,
        Statement::Block(b) => inside(b, false, false),
        Statement::If { accept, reject, .. } => inside(accept, false, false) || inside(reject, false, false),
        Statement::Switch { cases, .. } => cases.iter().any(|c| inside(&c.body, false, true)),
        Statement::Loop { body, continuing, .. } => inside(body, true, false) || inside(continuing, true, false),
        _ => false,
    }
}

/// The `select`s of `f` whose condition is a scalar bool: each picks one
/// arm per invocation, so each arm is counted.
fn scalar_selects(
    f: &Function,
    types: &naga::UniqueArena<Type>,
    info: Option<&naga::valid::FunctionInfo>,
) -> Vec<Handle<Expression>> {
    let Some(info) = info else { return Vec::new() };
    f.expressions
        .iter()
        .filter_map(|(h, e)| match e {
            Expression::Select { condition, .. } => {
                matches!(info[*condition].ty.inner_with(types), TypeInner::Scalar(s) if s.kind == naga::ScalarKind::Bool)
                    .then_some(h)
            }
            _ => None,
        })
        .collect()
}

/// The functions a vertex entry point calls, directly or not.
fn reached_from_vertex(m: &Module) -> Vec<Handle<Function>> {
    let mut reached: Vec<Handle<Function>> = Vec::new();
    let mut todo: Vec<&Block> =
        m.entry_points.iter().filter(|e| e.stage == ShaderStage::Vertex).map(|e| &e.function.body).collect();
    while let Some(block) = todo.pop() {
        let mut calls = Vec::new();
        calls_in(block, &mut calls);
        for f in calls {
            if !reached.contains(&f) {
                reached.push(f);
                todo.push(&m.functions[f].body);
            }
        }
    }
    reached
}

fn calls_in(block: &Block, out: &mut Vec<Handle<Function>>) {
    for s in block.iter() {
        match s {
            Statement::Call { function, .. } => out.push(*function),
            Statement::Block(b) => calls_in(b, out),
            Statement::If { accept, reject, .. } => {
                calls_in(accept, out);
                calls_in(reject, out);
            }
            Statement::Switch { cases, .. } => cases.iter().for_each(|c| calls_in(&c.body, out)),
            Statement::Loop { body, continuing, .. } => {
                calls_in(body, out);
                calls_in(continuing, out);
            }
            _ => {}
        }
    }
}

/// What adding a counter to a function needs.
struct Adder<'a> {
    expressions: &'a mut naga::Arena<Expression>,
    global: Handle<Expression>,
    one: Handle<Expression>,
    zero: Handle<Expression>,
    function: &'a str,
    counters: &'a mut Vec<Counter>,
    /// Scalar `select`s, whose arms get counters where they are emitted.
    selects: &'a [Handle<Expression>],
}

impl Adder<'_> {
    /// A new counter: its index and the two statements that add one to it.
    fn counter(&mut self, arm: Option<Arm>) -> (usize, [(Statement, Span); 2]) {
        self.counter_by(arm, None)
    }

    /// A new counter and the two statements that add one to it, or where
    /// `when` is given (a condition and whether it counts when true), one
    /// if the condition is so and none otherwise: no branch.
    fn counter_by(
        &mut self,
        arm: Option<Arm>,
        when: Option<(Handle<Expression>, bool)>,
    ) -> (usize, [(Statement, Span); 2]) {
        let index = self.counters.len();
        self.counters.push(Counter { spans: Vec::new(), arm, function: self.function.to_string(), derived: None });
        let span = arm.map_or(Span::UNDEFINED, |a| a.at);
        let amount = match when {
            None => None,
            Some((condition, on)) => {
                let (accept, reject) = if on { (self.one, self.zero) } else { (self.zero, self.one) };
                Some(self.expressions.append(Expression::Select { condition, accept, reject }, span))
            }
        };
        let pointer = self.expressions.append(Expression::AccessIndex { base: self.global, index: index as u32 }, span);
        let add =
            Statement::Atomic { pointer, fun: AtomicFunction::Add, value: amount.unwrap_or(self.one), result: None };
        // The emit starts at the condition's select where there is one.
        (
            index,
            [(Statement::Emit(naga::Range::new_from_bounds(amount.unwrap_or(pointer), pointer)), span), (add, span)],
        )
    }

    /// `block` with a counter at the start of each segment (and at its
    /// very start when it is an arm or `eager`, even if empty).
    /// `derived`: the block's first counter is that difference of two
    /// counters (an if's reject arm: the if's runs less its accept arm's)
    /// and adds nothing itself.
    fn block(&mut self, block: Block, arm: Option<Arm>, eager: bool, derived: Option<(usize, usize)>) -> Block {
        let mut out = Block::with_capacity(block.len() + 4);
        let mut open: Option<usize> = None;
        if let Some(derived) = derived {
            open = Some(self.counters.len());
            self.counters.push(Counter {
                spans: Vec::new(),
                arm,
                function: self.function.to_string(),
                derived: Some(derived),
            });
        } else if arm.is_some() || eager {
            let (index, adds) = self.counter(arm);
            adds.into_iter().for_each(|(s, sp)| out.push(s, sp));
            open = Some(index);
        }
        for (statement, span) in block.span_into_iter() {
            let index = match open {
                Some(i) => i,
                None => {
                    let (index, adds) = self.counter(None);
                    adds.into_iter().for_each(|(s, sp)| out.push(s, sp));
                    open = Some(index);
                    index
                }
            };
            if span.is_defined() {
                self.counters[index].spans.push(span);
            }
            // A statement that leaves, or that branches or loops and may
            // leave from inside, ends the segment: what follows it may run
            // another number of times. One that always comes back to the
            // next statement does not: the segment goes on past it.
            let ends = escapes(&statement);
            let (statement, ends) = match statement {
                Statement::If { condition, accept, reject } => {
                    let taken = self.counters.len();
                    let accept = self.block(accept, Some(Arm { at: span, branch: 0 }), true, None);
                    let reject = self.block(reject, Some(Arm { at: span, branch: 1 }), true, Some((index, taken)));
                    (Statement::If { condition, accept, reject }, ends)
                }
                Statement::Switch { selector, cases } => {
                    let cases = cases
                        .into_iter()
                        .enumerate()
                        .map(|(i, c)| naga::SwitchCase {
                            body: self.block(c.body, Some(Arm { at: span, branch: i as u32 }), true, None),
                            ..c
                        })
                        .collect();
                    (Statement::Switch { selector, cases }, ends)
                }
                Statement::Loop { body, continuing, break_if } => {
                    let body = self.block(body, Some(Arm { at: span, branch: 0 }), true, None);
                    let continuing = self.block(continuing, None, false, None);
                    (Statement::Loop { body, continuing, break_if }, ends)
                }
                Statement::Block(b) => (Statement::Block(self.block(b, None, false, None)), ends),
                s @ (Statement::Return { .. } | Statement::Break | Statement::Continue | Statement::Kill) => (s, true),
                s => (s, false),
            };
            let emitted = match &statement {
                Statement::Emit(range) => range.clone().filter(|h| self.selects.contains(h)).collect(),
                _ => Vec::new(),
            };
            out.push(statement, span);
            // A select's arms, right after the emit that evaluates it (its
            // condition is evaluated by then): the true arm's counter adds
            // the condition as 0 or 1, with no branch (an `if` per select
            // made llvmpipe's compile of the landscape kernel take minutes);
            // the false arm is its segment's runs less the true arm's.
            for h in emitted {
                let Expression::Select { condition, .. } = self.expressions[h] else { continue };
                let at = self.expressions.get_span(h);
                let (taken, adds) = self.counter_by(Some(Arm { at, branch: 0 }), Some((condition, true)));
                adds.into_iter().for_each(|(s, _)| out.push(s, Span::UNDEFINED));
                self.counters.push(Counter {
                    spans: Vec::new(),
                    arm: Some(Arm { at, branch: 1 }),
                    function: self.function.to_string(),
                    derived: Some((index, taken)),
                });
            }
            if ends {
                open = None;
            }
        }
        out
    }
}

fn instrument_function(
    f: &mut Function,
    global: Handle<naga::GlobalVariable>,
    name: &str,
    counters: &mut Vec<Counter>,
    selects: &[Handle<Expression>],
) {
    let global = f.expressions.append(Expression::GlobalVariable(global), Span::UNDEFINED);
    let one = f.expressions.append(Expression::Literal(Literal::U32(1)), Span::UNDEFINED);
    let zero = f.expressions.append(Expression::Literal(Literal::U32(0)), Span::UNDEFINED);
    let body = std::mem::take(&mut f.body);
    let mut adder = Adder { expressions: &mut f.expressions, global, one, zero, function: name, counters, selects };
    // The body starts a segment even if empty: a call of the function counts.
    f.body = adder.block(body, None, true, None);
}

#[cfg(test)]
mod tests;
