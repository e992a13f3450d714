//! Pass 4, bind arguments: every argument expression gets an argument slot (or a column entry)
//! and a compiled program, control-rate or audio-rate; initial positions and velocities become
//! init runs. Slots are laid out in this order: single masses' columns, each macro's slots,
//! connection-point coordinates, then each interaction group's columns.

use super::context::Cx;
use super::kinds::Kinds;
use super::points::Numbering;
use super::Rate;
use crate::laws::ArgClass;
use crate::laws::LawKind;
use crate::sim::engine::{
    InitRule, InitRun, Interactions, LineMacro, MacroSlots, Macros, MeshMacro, SingleMasses,
};
use crate::sim::kernels::masses::Update;
use crate::spec::expr::Expr;
use crate::spec::{ElementKind, MacroKind, SampleRateMode, REFERENCE_SAMPLE_RATE_HZ};

/// The bound kinds, ready to run.
pub(super) struct Bound {
    pub singles: SingleMasses,
    pub macros: Macros,
    pub interactions: Interactions,
    /// How each point starts (spec §1.5 stage 0).
    pub init_runs: Vec<InitRun>,
    /// Single masses with an audio-rate argument, re-derived every sample.
    pub audio_masses: Vec<u32>,
}

impl<'a> Cx<'a> {
    pub fn bind_arguments(
        &mut self,
        kinds: &Kinds<'a>,
        numbering: &Numbering,
        rate: Rate,
    ) -> Bound {
        let mut init_runs = Vec::new();
        let (singles, audio_masses) = self.bind_singles(&kinds.singles, rate, &mut init_runs);
        let macros = self.bind_macros(&numbering.macros, rate, &mut init_runs);
        for &(i, route) in &kinds.avatars {
            let ElementKind::PosInput { pos, .. } = &self.spec.elements[i].kind else {
                continue;
            };
            let (x0, _) = self.expr(pos.z(), i);
            init_runs.push(InitRun {
                first: route.index,
                count: 1,
                x0,
                rule: InitRule::Fixed,
            });
        }
        self.bind_connection_points();
        let interactions = self.bind_links(kinds);
        Bound {
            singles,
            macros,
            interactions,
            init_runs,
            audio_masses,
        }
    }

    /// Single masses: columns M, K, Z, gravity, one row per mass.
    fn bind_singles(
        &mut self,
        elements: &[usize],
        rate: Rate,
        init_runs: &mut Vec<InitRun>,
    ) -> (SingleMasses, Vec<u32>) {
        let n_single = elements.len();
        let cols = [0, 1, 2, 3].map(|c| self.args.len() + c * n_single);
        let new_len = self.args.len() + 4 * n_single;
        self.args.resize(new_len, 0.0);
        let mut singles = SingleMasses {
            a: vec![0.0; n_single],
            b: vec![0.0; n_single],
            inv_m: vec![0.0; n_single],
            gravity: vec![0.0; n_single],
            fixed: vec![false; n_single],
            audio: vec![false; n_single],
            force_set: vec![false; n_single],
            cols,
            runs: vec![(0, 0, Update::General, true); n_single],
            num_runs: 0,
        };
        let mut audio_masses = Vec::new();
        let zero = Expr::Num(0.0);
        for (row, &i) in elements.iter().enumerate() {
            let e = &self.spec.elements[i];
            let (m, k, z, g, gclass) = match &e.kind {
                ElementKind::Mass { m, gravity, .. } => {
                    (m, &zero, &zero, gravity, ArgClass::Gravity)
                }
                ElementKind::Osc {
                    m, k, z, gravity, ..
                } => (m, k, z, gravity, ArgClass::Gravity),
                ElementKind::MassG { m, gravity, .. } => {
                    (m, &zero, &zero, gravity, ArgClass::LegacyGravity)
                }
                _ => (&zero, &zero, &zero, &zero, ArgClass::None),
            };
            let fixed = matches!(e.kind, ElementKind::Ground { .. });
            singles.fixed[row] = fixed;
            if !fixed {
                self.check_constant(m, "mass M must be > 0", true, i);
            }
            let mut audio = false;
            audio |= self.bind(m, ArgClass::None, cols[0] + row, i);
            audio |= self.bind(k, ArgClass::Stiffness, cols[1] + row, i);
            audio |= self.bind(z, ArgClass::Damping, cols[2] + row, i);
            audio |= self.bind(g, gclass, cols[3] + row, i);
            if audio {
                audio_masses.push(row as u32);
                singles.audio[row] = true;
            }
            // Single masses are numbered first, in this order: row r is point r.
            let first = row as u32;
            let run = match &e.kind {
                ElementKind::Mass { pos, vel, .. } | ElementKind::Osc { pos, vel, .. } => {
                    let (x0, _) = self.expr(pos.z(), i);
                    let (v, _) = self.expr(vel.z(), i);
                    InitRun {
                        first,
                        count: 1,
                        x0,
                        rule: InitRule::Velocity {
                            v,
                            factor: rate.velocity_factor(),
                        },
                    }
                }
                ElementKind::MassG { pos, delayed, .. } => {
                    let (x0, _) = self.expr(pos.z(), i);
                    let (xr0, _) = self.expr(delayed.z(), i);
                    let factor = match rate.mode {
                        SampleRateMode::Scaled => REFERENCE_SAMPLE_RATE_HZ / rate.sr,
                        SampleRateMode::Raw => 1.0,
                    };
                    InitRun {
                        first,
                        count: 1,
                        x0,
                        rule: InitRule::Delayed { xr0, factor },
                    }
                }
                ElementKind::Ground { pos } => {
                    let (x0, _) = self.expr(pos.z(), i);
                    InitRun {
                        first,
                        count: 1,
                        x0,
                        rule: InitRule::Fixed,
                    }
                }
                _ => continue,
            };
            init_runs.push(run);
        }
        (singles, audio_masses)
    }

    /// Macros: five slots each (M, K, K2, Z, Zo) and one init run over their nodes.
    fn bind_macros(
        &mut self,
        elements: &[(usize, Vec<u32>)],
        rate: Rate,
        init_runs: &mut Vec<InitRun>,
    ) -> Macros {
        let mut macros = Macros::default();
        let mut largest_macro = 0;
        let zero = Expr::Num(0.0);
        for (i, fixed) in elements {
            let i = *i;
            let ElementKind::Macro(mac) = &self.spec.elements[i].kind else {
                continue;
            };
            let Some(base) = self.element_point[i] else {
                continue;
            };
            self.check_constant(&mac.m, "mass M must be > 0", true, i);
            let (m, _) = self.slot(&mac.m, ArgClass::None, i);
            let (k, _) = self.slot(&mac.k, ArgClass::Stiffness, i);
            let (k2, _) = self.slot(mac.k2.as_ref().unwrap_or(&zero), ArgClass::Stiffness, i);
            let (z, _) = self.slot(&mac.z, ArgClass::Damping, i);
            let (zo, _) = self.slot(&mac.zo, ArgClass::Damping, i);
            let slots = MacroSlots { m, k, k2, z, zo };
            let n = mac.num_nodes();
            // The mesh kernel keeps two rows of velocities.
            largest_macro = largest_macro.max(n).max(2 * mac.width as usize);
            let base_us = base as usize;
            let (x0, _) = self.expr(mac.pos.z(), i);
            let (v, _) = self.expr(mac.vel.z(), i);
            init_runs.push(InitRun {
                first: base,
                count: n as u32,
                x0,
                rule: InitRule::Velocity {
                    v,
                    factor: rate.velocity_factor(),
                },
            });
            match mac.kind {
                MacroKind::String | MacroKind::Chain => macros.lines.push(LineMacro {
                    base: base_us,
                    len: n,
                    fixed_ends: mac.kind == MacroKind::String,
                    slots,
                }),
                MacroKind::StiffString => macros.stiff.push(LineMacro {
                    base: base_us,
                    len: n,
                    fixed_ends: true,
                    slots,
                }),
                MacroKind::Mesh | MacroKind::CornerMesh | MacroKind::ClosedMesh => {
                    macros.meshes.push(MeshMacro::new(
                        base_us,
                        mac.length as usize,
                        mac.width as usize,
                        fixed.clone(),
                        slots,
                    ))
                }
            }
        }
        macros.scratch_v = vec![0.0; largest_macro];
        // The row sweep of a large mesh takes some rows of its own.
        let rows = crate::sim::kernels::mesh::SCRATCH_ROWS;
        let widest = macros
            .meshes
            .iter()
            .map(|m| rows * m.width)
            .max()
            .unwrap_or(0);
        macros.scratch_s = vec![0.0; largest_macro.max(widest)];
        macros
    }

    /// Connection points: two coordinate slots each (α and 0, or u and w), in creation order.
    fn bind_connection_points(&mut self) {
        let coords = std::mem::take(&mut self.proxy_coords);
        for (index, &(element, [c0, c1])) in coords.iter().enumerate() {
            let (s0, audio0) = self.slot(c0, ArgClass::None, element);
            let (s1, audio1) = self.slot(c1, ArgClass::None, element);
            self.proxies.coord_slots.push([s0, s1]);
            if audio0 || audio1 {
                // Recomputed every sample.
                self.proxy_audio.push(index as u32);
            }
        }
        self.proxy_coords = coords;
    }

    /// Interaction groups: one column per argument, one row per link.
    fn bind_links(&mut self, kinds: &Kinds<'a>) -> Interactions {
        let mut interactions = Interactions::default();
        for ((rows, group), kind) in kinds
            .links
            .groups
            .iter()
            .zip(interactions.groups_mut())
            .zip(LawKind::ALL)
        {
            let ncols = kind.arity();
            let n = rows.len();
            group.cols = (0..ncols).map(|c| self.args.len() + c * n).collect();
            let new_len = self.args.len() + ncols * n;
            self.args.resize(new_len, 0.0);
            for (r, row) in rows.iter().enumerate() {
                group.a.push(row.a);
                group.b.push(row.b);
                group.elements.push(row.element as u32);
                for (c, (expr, class)) in row.args.iter().take(ncols).enumerate() {
                    let slot = group.cols[c] + r;
                    self.bind(expr, *class, slot, row.element);
                }
            }
        }
        interactions
    }
}
