//! The symbol table of a script: every label, what it names and where it was declared
//! (spec §3.4), for name resolution and endpoint checks.

use crate::spec::label_map::LabelMap;
use std::borrow::Cow;
use std::collections::hash_map::Entry;
use std::collections::HashSet;

/// What a label names, for name resolution and endpoint checks (spec §3.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SymKind {
    /// `param` or `audioParam`.
    Param,
    /// A mass-type element or an avatar: a valid endpoint.
    Point,
    /// A macro addressed with `dims` connection coordinates (1 or 2; a byte keeps the symbol
    /// table's buckets small).
    Macro {
        dims: u8,
    },
    Interaction,
    FrcInput,
    Output,
    /// A line whose keyword is unknown: references to it are not checked (no cascades).
    Unknown,
}

impl SymKind {
    pub(crate) fn describe(self) -> &'static str {
        match self {
            SymKind::Param => "a parameter",
            SymKind::Point => "a point",
            SymKind::Macro { .. } => "a macro",
            SymKind::Interaction => "an interaction",
            SymKind::FrcInput => "a force input",
            SymKind::Output => "an output",
            SymKind::Unknown => "an element of unknown type",
        }
    }
}

/// A declared label: what it names and where it was declared.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Symbol {
    pub kind: SymKind,
    pub line: u32,
    pub col: u32,
    /// Declared by a `~generate` directive (at `line:col`) rather than by a command.
    pub generated: bool,
}

/// Every label of a script (spec §3.4), for name resolution and endpoint checks. A command's
/// label borrows the script's text; a generated one is owned.
#[derive(Debug, Default)]
pub(crate) struct Symbols<'a> {
    map: LabelMap<Cow<'a, str>, Symbol>,
    /// Some label names a macro: only then can an endpoint be a legacy bare connection point.
    has_macros: bool,
    /// Names of `~generate` directives that have an error: their labels are not known, so any
    /// `<name>_…` that is not declared otherwise resolves to [`SymKind::Unknown`] and
    /// references to it are not reported again (no cascades).
    broken_generators: HashSet<String>,
}

impl<'a> Symbols<'a> {
    /// An empty table with room for `labels` labels.
    pub(crate) fn with_capacity(labels: usize) -> Symbols<'a> {
        Symbols {
            map: LabelMap::with_capacity_and_hasher(labels, Default::default()),
            ..Symbols::default()
        }
    }

    /// The symbol named `name`: a declared label, or an unknown one under a broken generator.
    pub(crate) fn get(&self, name: &str) -> Option<Symbol> {
        if let Some(s) = self.map.get(name) {
            return Some(*s);
        }
        let under_broken = name
            .char_indices()
            .filter(|&(_, c)| c == '_')
            .any(|(i, _)| self.broken_generators.contains(name.get(..i).unwrap_or("")));
        under_broken.then_some(Symbol {
            kind: SymKind::Unknown,
            line: 0,
            col: 0,
            generated: true,
        })
    }

    /// The symbol declared as `name`, ignoring broken generators.
    pub(crate) fn declared(&self, name: &str) -> Option<Symbol> {
        self.map.get(name).copied()
    }

    pub(crate) fn insert(&mut self, name: impl Into<Cow<'a, str>>, symbol: Symbol) {
        self.has_macros |= matches!(symbol.kind, SymKind::Macro { .. });
        self.map.insert(name.into(), symbol);
    }

    /// Declares `name` as `symbol`, unless it is declared already: then returns the name and
    /// the earlier declaration.
    pub(crate) fn declare(
        &mut self,
        name: impl Into<Cow<'a, str>>,
        symbol: Symbol,
    ) -> Result<(), (String, Symbol)> {
        match self.map.entry(name.into()) {
            Entry::Occupied(prev) => Err((prev.key().to_string(), *prev.get())),
            Entry::Vacant(slot) => {
                self.has_macros |= matches!(symbol.kind, SymKind::Macro { .. });
                slot.insert(symbol);
                Ok(())
            }
        }
    }

    /// True when some declared label names a macro.
    pub(crate) fn has_macros(&self) -> bool {
        self.has_macros
    }

    /// Records a `~generate` directive named `name` whose labels could not be worked out.
    pub(crate) fn insert_broken_generator(&mut self, name: String) {
        self.broken_generators.insert(name);
    }
}
