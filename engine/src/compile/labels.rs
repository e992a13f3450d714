//! Pass 1, resolve labels: parameters and elements share one label space (spec §3.4). Builds
//! the symbol table, reports duplicate labels and invalid parameter names, and reads every
//! parameter's declared value and audio input.

use super::context::{Cx, Role, Symbol};
use super::errors::{CompileError, CompileErrorKind};
use crate::sim::engine::Route;
use crate::sim::info::ParamInfo;
use crate::spec::expr::Func;
use crate::spec::label_map::LabelKey;
use crate::spec::ParamKind;
use std::collections::hash_map::Entry;

/// The parameters, by id.
pub(super) struct Params {
    /// Declared values (an audio-rate parameter's default); 0 where not finite.
    pub values: Vec<f64>,
    pub info: Vec<ParamInfo>,
    /// Audio-rate parameters and their inputs.
    pub audio: Vec<Route>,
}

impl Cx<'_> {
    pub fn resolve_labels(&mut self) -> Params {
        let spec = self.spec;
        // The first declaration of a label wins; a later one is reported with its span.
        for (id, p) in spec.params.iter().enumerate() {
            match self.symbols.entry(LabelKey(&p.name)) {
                Entry::Occupied(first) => {
                    let first = symbol_span(self.spec, *first.get());
                    self.errors.push(CompileError {
                        kind: CompileErrorKind::DuplicateLabel { first },
                        label: p.name.clone(),
                        span: p.span,
                    });
                    continue;
                }
                Entry::Vacant(slot) => {
                    slot.insert(Symbol::Param(id as u32));
                }
            }
            if !is_identifier(&p.name) || Func::from_name(&p.name).is_some() {
                self.errors.push(CompileError {
                    kind: CompileErrorKind::InvalidParamName,
                    label: p.name.clone(),
                    span: p.span,
                });
            }
        }
        for (i, e) in spec.elements.iter().enumerate() {
            match self.symbols.entry(LabelKey(&e.label)) {
                Entry::Occupied(first) => {
                    let first = symbol_span(self.spec, *first.get());
                    self.error(Some(i), CompileErrorKind::DuplicateLabel { first });
                }
                Entry::Vacant(slot) => {
                    slot.insert(Symbol::Element(i, Role::of(&e.kind)));
                }
            }
        }

        let mut values = Vec::with_capacity(spec.params.len());
        let mut info = Vec::with_capacity(spec.params.len());
        let mut audio = Vec::new();
        for (id, p) in spec.params.iter().enumerate() {
            let (value, audio_input) = match p.kind {
                ParamKind::Control { value } => {
                    if !value.is_finite() {
                        self.errors.push(CompileError {
                            kind: CompileErrorKind::InvalidValue {
                                what: "a parameter value must be finite",
                                value,
                            },
                            label: p.name.clone(),
                            span: p.span,
                        });
                    }
                    (value, None)
                }
                ParamKind::Audio { input, default } => {
                    if !default.is_finite() {
                        self.errors.push(CompileError {
                            kind: CompileErrorKind::InvalidValue {
                                what: "an audio-rate parameter's default must be finite",
                                value: default,
                            },
                            label: p.name.clone(),
                            span: p.span,
                        });
                    }
                    if input == 0 {
                        self.errors.push(CompileError {
                            kind: CompileErrorKind::InvalidChannel,
                            label: p.name.clone(),
                            span: p.span,
                        });
                    } else {
                        audio.push(Route {
                            channel: input - 1,
                            index: id as u32,
                        });
                    }
                    (default, Some(input))
                }
            };
            values.push(if value.is_finite() { value } else { 0.0 });
            self.param_is_audio.push(audio_input.is_some());
            self.param_is_coordinate.push(false);
            info.push(ParamInfo {
                name: p.name.clone(),
                default: value,
                audio_input,
                coordinate: false,
            });
        }
        Params {
            values,
            info,
            audio,
        }
    }
}

/// Where the label a symbol stands for was declared.
fn symbol_span(spec: &crate::spec::ModelSpec, symbol: Symbol) -> crate::spec::Span {
    match symbol {
        Symbol::Param(id) => spec.params[id as usize].span,
        Symbol::Element(i, _) => spec.elements[i].span,
    }
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}
