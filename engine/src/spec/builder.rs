//! [`ModelBuilder`]: a [`ModelSpec`] written in Rust instead of a script.

use super::*;

/// Builds a [`ModelSpec`] from Rust, in script order. Arguments take anything that converts
/// into an [`Expr`]: an `f64` literal, a `&str` parameter name, or an expression tree.
///
/// ```
/// use ressort_engine::{Endpoint, Law, LawKind, ModelBuilder, MacroKind};
/// let mut b = ModelBuilder::new();
/// b.param("K", 0.1).param("Z", 0.001);
/// b.macro_1d("s", MacroKind::String, 42, 1.0, "K", "Z");
/// b.interaction("hit", Law::new(LawKind::Contact, [0.1.into(), 0.001.into(), 0.0.into()]),
///               Endpoint::at("s", 0.13), Endpoint::label("h"));
/// b.mass("h", 1.0, 0.1, 0.0);
/// b.frc_input(1, Endpoint::label("h"));
/// b.pos_output(1, Endpoint::at("s", 0.77));
/// let spec = b.build();
/// assert_eq!(spec.elements.len(), 5);
/// ```
#[derive(Debug, Default)]
pub struct ModelBuilder {
    spec: ModelSpec,
    open_scopes: Vec<u32>,
}

impl ModelBuilder {
    pub fn new() -> ModelBuilder {
        ModelBuilder::default()
    }

    /// Switches the whole model to raw per-step values (`~samplerate raw`).
    pub fn raw(&mut self) -> &mut Self {
        self.spec.sample_rate_mode = SampleRateMode::Raw;
        self
    }

    /// `@name param value`.
    pub fn param(&mut self, name: &str, value: f64) -> &mut Self {
        self.spec.params.push(ParamDecl {
            name: name.to_string(),
            kind: ParamKind::Control { value },
            span: Span::default(),
        });
        self
    }

    /// `@name audioParam @inN` (default 0).
    pub fn audio_param(&mut self, name: &str, input: u32) -> &mut Self {
        self.audio_param_with_default(name, input, 0.0)
    }

    /// `@name audioParam @inN default`: default + input N.
    pub fn audio_param_with_default(&mut self, name: &str, input: u32, default: f64) -> &mut Self {
        self.spec.params.push(ParamDecl {
            name: name.to_string(),
            kind: ParamKind::Audio { input, default },
            span: Span::default(),
        });
        self
    }

    /// `~begin name`: points created from now on also join the named buffer.
    pub fn begin_scope(&mut self, name: &str) -> &mut Self {
        let id = match self.spec.buffers.iter().position(|b| b == name) {
            Some(i) => i as u32,
            None => {
                self.spec.buffers.push(name.to_string());
                (self.spec.buffers.len() - 1) as u32
            }
        };
        if !self.open_scopes.contains(&id) {
            self.open_scopes.push(id);
        }
        self
    }

    /// `~end name`.
    pub fn end_scope(&mut self, name: &str) -> &mut Self {
        if let Some(i) = self.spec.buffers.iter().position(|b| b == name) {
            self.open_scopes.retain(|&s| s != i as u32);
        }
        self
    }

    /// Appends an element with the currently open scopes.
    pub fn element(&mut self, label: &str, kind: ElementKind) -> &mut Self {
        self.spec.elements.push(Element {
            label: label.into(),
            kind,
            buffers: self.open_scopes.clone(),
            tag_xy: None,
            span: Span::default(),
        });
        self
    }

    /// `@label mass M pos vel` (no gravity).
    pub fn mass(
        &mut self,
        label: &str,
        m: impl Into<Expr>,
        pos: impl Into<Vector>,
        vel: impl Into<Vector>,
    ) -> &mut Self {
        self.mass_with_gravity(label, m, 0.0, pos, vel)
    }

    /// `@label mass M gravity pos vel`.
    pub fn mass_with_gravity(
        &mut self,
        label: &str,
        m: impl Into<Expr>,
        gravity: impl Into<Expr>,
        pos: impl Into<Vector>,
        vel: impl Into<Vector>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Mass {
                m: m.into(),
                gravity: gravity.into(),
                pos: pos.into(),
                vel: vel.into(),
            },
        )
    }

    /// `@label osc M K Z pos vel` (no gravity).
    pub fn osc(
        &mut self,
        label: &str,
        m: impl Into<Expr>,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
        pos: impl Into<Vector>,
        vel: impl Into<Vector>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Osc {
                m: m.into(),
                k: k.into(),
                z: z.into(),
                gravity: Expr::Num(0.0),
                pos: pos.into(),
                vel: vel.into(),
            },
        )
    }

    /// `@label ground pos`.
    pub fn ground(&mut self, label: &str, pos: impl Into<Vector>) -> &mut Self {
        self.element(label, ElementKind::Ground { pos: pos.into() })
    }

    /// A 1-D macro (`string`, `chain`) of `nodes` nodes at rest at 0, without ground friction.
    pub fn macro_1d(
        &mut self,
        label: &str,
        kind: MacroKind,
        nodes: u32,
        m: impl Into<Expr>,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Macro(Box::new(MacroSpec {
                kind,
                length: nodes,
                width: 1,
                m: m.into(),
                k: k.into(),
                k2: None,
                z: z.into(),
                zo: Expr::Num(0.0),
                pos: 0.0.into(),
                vel: 0.0.into(),
            })),
        )
    }

    /// A mesh macro of `length × width` nodes at rest at 0, without ground friction.
    pub fn mesh(
        &mut self,
        label: &str,
        kind: MacroKind,
        length: u32,
        width: u32,
        m: impl Into<Expr>,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Macro(Box::new(MacroSpec {
                kind,
                length,
                width,
                m: m.into(),
                k: k.into(),
                k2: None,
                z: z.into(),
                zo: Expr::Num(0.0),
                pos: 0.0.into(),
                vel: 0.0.into(),
            })),
        )
    }

    /// Any macro, fully specified.
    pub fn macro_spec(&mut self, label: &str, spec: MacroSpec) -> &mut Self {
        self.element(label, ElementKind::Macro(Box::new(spec)))
    }

    /// An interaction `@label <law> a b args…`.
    pub fn interaction(&mut self, label: &str, law: Law, a: Endpoint, b: Endpoint) -> &mut Self {
        self.element(label, ElementKind::Interaction { law, a, b })
    }

    /// `@label springDamper a b K Z`.
    pub fn spring_damper(
        &mut self,
        label: &str,
        a: Endpoint,
        b: Endpoint,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
    ) -> &mut Self {
        self.interaction(
            label,
            Law::new(LawKind::SpringDamper, [k.into(), z.into()]),
            a,
            b,
        )
    }

    /// `@label contact a b K Z thresh`.
    pub fn contact(
        &mut self,
        label: &str,
        a: Endpoint,
        b: Endpoint,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
        thresh: impl Into<Expr>,
    ) -> &mut Self {
        self.interaction(
            label,
            Law::new(LawKind::Contact, [k.into(), z.into(), thresh.into()]),
            a,
            b,
        )
    }

    /// `@inN posInput pos`.
    pub fn pos_input(&mut self, channel: u32, pos: impl Into<Vector>) -> &mut Self {
        self.element(
            &format!("in{channel}"),
            ElementKind::PosInput {
                channel,
                pos: pos.into(),
            },
        )
    }

    /// `@inN frcInput target`.
    pub fn frc_input(&mut self, channel: u32, target: Endpoint) -> &mut Self {
        self.element(
            &format!("in{channel}"),
            ElementKind::FrcInput { channel, target },
        )
    }

    /// `@outN posOutput target`.
    pub fn pos_output(&mut self, channel: u32, target: Endpoint) -> &mut Self {
        self.element(
            &format!("out{channel}"),
            ElementKind::PosOutput { channel, target },
        )
    }

    /// `@outN frcOutput target`.
    pub fn frc_output(&mut self, channel: u32, target: Endpoint) -> &mut Self {
        self.element(
            &format!("out{channel}"),
            ElementKind::FrcOutput { channel, target },
        )
    }

    /// The finished spec.
    pub fn build(&self) -> ModelSpec {
        self.spec.clone()
    }

    /// The finished spec, without copying it.
    pub fn finish(self) -> ModelSpec {
        self.spec
    }
}
