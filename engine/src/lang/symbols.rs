//! The symbol table of a script: every label, what it names and where it was declared
//! (spec §3.4), for name resolution and endpoint checks.

use crate::spec::label_map::LabelMap;
use crate::spec::space::structures::{self, Counts};
use crate::spec::space::{MeshData, StructureKind};
use std::borrow::Cow;
use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};
use std::sync::Arc;

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
    /// The structures and adders of a 3-D script (3-D spec §4.0, §4.7), by label: the labels
    /// they create (`s_m12`, `s_r3`, `h_7`) are resolved from their counts rather than stored
    /// one by one.
    generators: HashMap<String, Generated>,
}

/// What a 3-D structure or adder creates, for resolving its labels.
#[derive(Clone, Debug)]
pub(crate) struct Generated {
    /// The generator, with its sizes; `None` for an adder (`contactSet`, `vdampers`), whose
    /// labels are `<name>_<k>` for `k < adds`.
    pub structure: Option<(StructureKind, Vec<u32>)>,
    pub counts: Counts,
    /// The links an adder creates.
    pub adds: u64,
    pub line: u32,
    pub col: u32,
    /// objMesh: the file, read in pass 1.
    pub mesh: Option<Arc<MeshData>>,
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
        if under_broken {
            return Some(Symbol {
                kind: SymKind::Unknown,
                line: 0,
                col: 0,
                generated: true,
            });
        }
        self.generated(name).map(|(_, symbol)| symbol)
    }

    /// The 3-D structure or adder that creates the label `name`, and what the label names: a
    /// node (`s_m12`) is a point, a link (`s_r3`, `h_7`) an interaction.
    pub(crate) fn generated<'n>(&self, name: &'n str) -> Option<(&'n str, Symbol)> {
        if self.generators.is_empty() {
            return None;
        }
        for (i, _) in name.char_indices().filter(|&(_, c)| c == '_') {
            let (owner, suffix) = (name.get(..i)?, name.get(i + 1..)?);
            let Some(g) = self.generators.get(owner) else {
                continue;
            };
            let kind = match &g.structure {
                Some((kind, sizes)) => {
                    let node = suffix.strip_prefix('m').is_some_and(|s| {
                        structures::parse_node(*kind, sizes, g.counts.nodes, s).is_some()
                    });
                    if node {
                        SymKind::Point
                    } else if structures::is_link_label(&g.counts, suffix) {
                        SymKind::Interaction
                    } else {
                        continue;
                    }
                }
                None => {
                    let ok = !suffix.is_empty()
                        && suffix.chars().all(|c| c.is_ascii_digit())
                        && (suffix == "0" || !suffix.starts_with('0'))
                        && suffix.parse::<u64>().is_ok_and(|k| k < g.adds);
                    if !ok {
                        continue;
                    }
                    SymKind::Interaction
                }
            };
            let symbol = Symbol {
                kind,
                line: g.line,
                col: g.col,
                generated: true,
            };
            return Some((owner, symbol));
        }
        None
    }

    /// Records a 3-D structure or adder labelled `name`.
    pub(crate) fn insert_generator(&mut self, name: &str, g: Generated) {
        self.generators.insert(name.to_string(), g);
    }

    /// The 3-D structure or adder labelled `name`.
    pub(crate) fn generator(&self, name: &str) -> Option<&Generated> {
        self.generators.get(name)
    }

    /// Every declared label, for the collision check against generated ones.
    pub(crate) fn declared_labels(&self) -> impl Iterator<Item = (&str, &Symbol)> {
        self.map.iter().map(|(k, v)| (k.as_ref(), v))
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
