//! Stage 4 of spec §1.5: the interactions, one loop per law (spec §2.3–§2.6), over endpoint
//! index arrays, with chains and bands of links run as contiguous loops.

use super::Points;
use crate::laws::{Law, LawKind, LawVisitor, Scalar};
use std::ops::Range;

/// Interactions of one law: endpoint index arrays and argument columns in `Engine::args`
/// (column c of row i is `args[cols[c] + i]`).
#[derive(Clone, Debug, Default)]
pub(crate) struct Group {
    pub a: Vec<u32>,
    pub b: Vec<u32>,
    pub cols: Vec<usize>,
    /// The spec element each link comes from (cold: diagnostics point at its line).
    pub elements: Vec<u32>,
    /// Bands, in list order: runs of at least [`MIN_CHAIN`] links at positions
    /// `start..start + len` with link j = (q + j, q + j + d), as (start, len, d) — a string
    /// or a mesh row written element by element (d = 1), a mesh's links between rows
    /// (d = its width). See [`Group::apply`].
    pub chains: Vec<(u32, u32, u32)>,
    /// Per chain: every link's arguments are equal (column by column, bit for bit, before
    /// the class factors), so the law reads the first link's and the loop streams no
    /// argument ([`Group::find_uniform`]).
    pub uniform: Vec<bool>,
    /// Per chain: an argument is audio-rate (it may change within a block) or a column
    /// mixes scaling classes: never uniform.
    pub varying: Vec<bool>,
    /// Per chain: its links are written the other way round, link j = (q + j + d, q + j)
    /// (a string written from its far end); see [`Group::apply`].
    pub reversed: Vec<bool>,
    /// Per chain: the number of chains, this one first, that are the rows of one mesh (see
    /// [`Group::find_rows`]); 0 when it starts none.
    pub rows: Vec<u32>,
    /// Per chain starting rows: every row is uniform with the same arguments, so the rows
    /// run as one loop ([`Group::find_uniform`]).
    pub rows_uniform: Vec<bool>,
    /// Per chain: the band is the first interaction of stage 4 to write the force of each of
    /// its points, all single masses, so it sets their F instead of adding to the +0 the mass
    /// pass would have left, and the mass pass does not clear them
    /// ([`Interactions::find_setters`]). The bits are the same: F + s with F = +0 is 0.0 + s.
    pub sets: Vec<bool>,
}

/// The size [`Engine`](crate::Engine)'s doc comment counts: eleven vector headers.
#[cfg(target_arch = "x86_64")]
const _: () = assert!(std::mem::size_of::<Group>() == 264);

/// The shortest run of links [`Group::apply`] runs as a chain.
pub(crate) const MIN_CHAIN: usize = 4;

/// The shortest uniform chain that runs without argument streams: the compiler unrolls that
/// loop further, so shorter ones (mesh rows) would run in its scalar remainder.
const UNIFORM_MIN: usize = 64;

/// Links per tile of a long forward band: its forces live in a window of `TILE + d` scratch
/// values instead of one per link, so that a 1000-link string's positions, delayed
/// positions and forces (24 KB) stay in a 32 KB L1 cache with room to spare.
const TILE: usize = 256;

impl Group {
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// Finds the bands (done once, when the model is compiled).
    pub fn find_chains(&mut self) {
        let (chains, reversed) = find_bands(&self.a, &self.b);
        self.chains = chains;
        self.reversed = reversed;
        self.uniform = vec![false; self.chains.len()];
        self.varying = vec![false; self.chains.len()];
        self.rows = vec![0; self.chains.len()];
        self.rows_uniform = vec![false; self.chains.len()];
        self.sets = vec![false; self.chains.len()];
    }

    /// Finds the rows of meshes written element by element (done once, when the model is
    /// compiled): at least two chains of m links with d = 1, one after the other in the list,
    /// each starting m + 1 points after the previous one, over single masses only (points
    /// below `singles`, whose F is +0 when stage 4 starts: the mass pass clears it, or the
    /// rows set it, [`Group::sets`]).
    ///
    /// Such rows run as one chain over all their points (see [`Group::apply`]) in which the
    /// links that are not there (from a row's last point to the next row's first) have force
    /// exactly +0. That changes no bit: at a row's end (F + s) − (+0) is F + s, and at the next
    /// row's start (F + (+0)) − s is F − s because F is never −0 there (it starts at +0, or
    /// at a force an earlier band set from +0, and in round-to-nearest a sum or difference is
    /// −0 only when its first operand is −0).
    pub fn find_rows(&mut self, singles: usize) {
        let n = self.chains.len();
        let mut c = 0;
        while c < n {
            let (start, m, d) = self.chains[c];
            let q = self.a[start as usize];
            let mut end = c + 1;
            while end < n && d == 1 && !self.reversed[c] {
                let (s2, m2, d2) = self.chains[end];
                let k = (end - c) as u32;
                if d2 != 1
                    || self.reversed[end]
                    || m2 != m
                    || s2 != start + k * m
                    || self.a[s2 as usize] != q + k * (m + 1)
                {
                    break;
                }
                end += 1;
            }
            let rows = end - c;
            let last_point = q as usize + rows * (m as usize + 1) - 1;
            if rows >= 2 && last_point < singles {
                self.rows[c] = rows as u32;
            }
            c = end;
        }
    }

    /// Marks as varying the chains with an audio-rate argument (`audio`: one flag per slot of
    /// the engine's arguments) or a column that mixes scaling classes (`class`: one per slot),
    /// whose equal arguments before the factors need not stay equal. Done once, when the
    /// model is compiled.
    pub fn mark_varying(&mut self, audio: &[bool], class: &[u8]) {
        for (c, &(start, len, _)) in self.chains.iter().enumerate() {
            let range = start as usize..(start + len) as usize;
            self.varying[c] = self.cols.iter().any(|&col| {
                let slots = col + range.start..col + range.end;
                let classes = &class[slots.clone()];
                audio[slots].contains(&true) || classes.iter().any(|&k| k != classes[0])
            });
        }
    }

    /// The points band `c` writes: its links' first ends q … q + m − 1 and second ends
    /// q + d … q + d + m − 1, q its lower point.
    fn band_points(&self, c: usize) -> std::iter::Chain<Range<usize>, Range<usize>> {
        let (start, m, d) = self.chains[c];
        let lower = if self.reversed[c] { &self.b } else { &self.a };
        let (q, m, d) = (lower[start as usize] as usize, m as usize, d as usize);
        (q..q + m).chain(q + d..q + d + m)
    }

    /// Marks both ends of links `links` as written (see [`Interactions::find_setters`]).
    fn mark_links(&self, links: Range<usize>, written: &mut [bool]) {
        for k in links {
            written[self.a[k] as usize] = true;
            written[self.b[k] as usize] = true;
        }
    }

    /// Recomputes which chains are uniform from the arguments before their class factors
    /// (`raw`: a column has one class, so equal there means equal at any factor), after a
    /// parameter changed. Never allocates.
    pub fn find_uniform(&mut self, raw: &[f64]) {
        for (c, &(start, len, _)) in self.chains.iter().enumerate() {
            let range = start as usize..(start + len) as usize;
            self.uniform[c] = !self.varying[c]
                && self.cols.iter().all(|&col| {
                    let v = &raw[col + range.start..col + range.end];
                    let first = v[0].to_bits();
                    v.iter().all(|a| a.to_bits() == first)
                });
        }
        for c in 0..self.chains.len() {
            let rows = self.rows[c] as usize;
            let first = self.chains[c].0 as usize;
            self.rows_uniform[c] = rows > 0
                && (c..c + rows).all(|r| {
                    let start = self.chains[r].0 as usize;
                    self.uniform[r]
                        && self
                            .cols
                            .iter()
                            .all(|&col| raw[col + start].to_bits() == raw[col + first].to_bits())
                });
        }
    }

    /// The longest chain's length, rows of a mesh counting as one chain over all their points.
    pub fn longest_chain(&self) -> usize {
        let rows = self
            .chains
            .iter()
            .zip(&self.rows)
            .map(|(c, &r)| r as usize * (c.1 as usize + 1));
        self.chains
            .iter()
            .map(|c| c.1 as usize)
            .chain(rows)
            .max()
            .unwrap_or(0)
    }

    #[inline(always)]
    fn col<'a>(&self, args: &'a [f64], c: usize) -> &'a [f64] {
        &args[self.cols[c]..self.cols[c] + self.len()]
    }

    /// Applies `law(i, Δx, Δv)` to every pair with the convention of spec §1.3:
    /// F₁ −= f, F₂ += f, link by link in list order.
    ///
    /// A band (links (q + j, q + j + d), j = 0..m) runs as contiguous loops that vectorise:
    /// the forces s_j, then every point's sum ([`forward_sums`], [`reversed_sums`]), the
    /// link-by-link scatter's arithmetic exactly without its store-to-load chain through
    /// shared points. A band that [`Group::sets`] its points' forces does not read them.
    #[inline(always)]
    fn apply(&self, p: &mut Points, law: impl Fn(usize, f64, f64) -> f64) {
        let n = self.len();
        let (a, b) = (&self.a[..n], &self.b[..n]);
        // Local slices: the stores to `f` cannot move the arrays, so their pointers and
        // lengths stay in registers.
        let (x, xp, f, scratch) = (&p.x[..], &p.xp[..], &mut p.f[..], &mut p.s[..]);
        let mut i = 0;
        let mut c = 0;
        while c < self.chains.len() {
            let (start, len, d) = self.chains[c];
            let (start, m, d) = (start as usize, len as usize, d as usize);
            let uniform = self.uniform.get(c).copied().unwrap_or(false);
            let sets = self.sets.get(c).copied().unwrap_or(false);
            scatter(i, &a[i..start], &b[i..start], x, xp, f, &law);
            let q = a[start] as usize;
            if self.rows_uniform.get(c).copied().unwrap_or(false) {
                // Rows of a mesh as one chain over all their points (see `find_rows`).
                let rows = self.rows[c] as usize;
                let w = m + 1;
                let total = rows * w - 1;
                let (xs, xps) = (&x[q..q + total + 1], &xp[q..q + total + 1]);
                let s = &mut scratch[..total];
                for j in 0..total {
                    let dx = xs[j] - xs[j + 1];
                    let dv = (xs[j] - xps[j]) - (xs[j + 1] - xps[j + 1]);
                    s[j] = law(start, dx, dv);
                }
                for r in 1..rows {
                    s[r * w - 1] = 0.0;
                }
                // A rows block sets its forces only if all its rows do (`find_setters`).
                let fs = &mut f[q..q + total + 1];
                if sets {
                    forward_sums::<true>(fs, s, total, 1);
                } else {
                    forward_sums::<false>(fs, s, total, 1);
                }
                i = start + rows * m;
                c += rows;
                continue;
            }
            if self.reversed.get(c).copied().unwrap_or(false) {
                // Link j = (q + j + d, q + j), q its lower point: Δx = x[q + j + d] − x[q + j],
                // F[q + j + d] −= s_j, F[q + j] += s_j.
                let q = b[start] as usize;
                let (xl, xh) = (&x[q..q + m], &x[q + d..q + d + m]);
                let (xpl, xph) = (&xp[q..q + m], &xp[q + d..q + d + m]);
                let s = &mut scratch[..m];
                band_forces(
                    start,
                    uniform && m >= UNIFORM_MIN,
                    xh,
                    xl,
                    xph,
                    xpl,
                    s,
                    &law,
                );
                let fs = &mut f[q..q + m + d];
                if sets {
                    reversed_sums::<true>(fs, s, m, d);
                } else {
                    reversed_sums::<false>(fs, s, m, d);
                }
                i = start + m;
                c += 1;
                continue;
            }
            let (xa, xb) = (&x[q..q + m], &x[q + d..q + d + m]);
            let (xpa, xpb) = (&xp[q..q + m], &xp[q + d..q + d + m]);
            if m >= 2 * TILE && d <= TILE {
                let fs = &mut f[q..q + m + d];
                let band = (start, m, d, uniform);
                if sets {
                    forward_band_tiled::<true>(band, xa, xb, xpa, xpb, fs, scratch, &law);
                } else {
                    forward_band_tiled::<false>(band, xa, xb, xpa, xpb, fs, scratch, &law);
                }
                i = start + m;
                c += 1;
                continue;
            }
            let s = &mut scratch[..m];
            band_forces(
                start,
                uniform && m >= UNIFORM_MIN,
                xa,
                xb,
                xpa,
                xpb,
                s,
                &law,
            );
            let fs = &mut f[q..q + m + d];
            if sets {
                forward_sums::<true>(fs, s, m, d);
            } else {
                forward_sums::<false>(fs, s, m, d);
            }
            i = start + m;
            c += 1;
        }
        scatter(i, &a[i..], &b[i..], x, xp, f, &law);
    }
}

/// The forces s_j = law(link, Δx, Δv) of a band's links j = 0 … s.len() − 1, with
/// Δx = x₁ − x₂ and Δv = (x₁ − x̃₁) − (x₂ − x̃₂) from their first and second ends' positions.
/// Link j is number `first + j`; when `uniform`, every link's arguments are the first one's,
/// read once, outside the loop.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn band_forces(
    first: usize,
    uniform: bool,
    x1: &[f64],
    x2: &[f64],
    xp1: &[f64],
    xp2: &[f64],
    s: &mut [f64],
    law: &impl Fn(usize, f64, f64) -> f64,
) {
    let m = s.len();
    let (x1, x2, xp1, xp2) = (&x1[..m], &x2[..m], &xp1[..m], &xp2[..m]);
    if uniform {
        for j in 0..m {
            let dx = x1[j] - x2[j];
            let dv = (x1[j] - xp1[j]) - (x2[j] - xp2[j]);
            s[j] = law(first, dx, dv);
        }
    } else {
        for j in 0..m {
            let dx = x1[j] - x2[j];
            let dv = (x1[j] - xp1[j]) - (x2[j] - xp2[j]);
            s[j] = law(first + j, dx, dv);
        }
    }
}

/// A long forward band (links (q + j, q + j + d), j = 0..m, `m ≥ 2·TILE`, `d ≤ TILE`) in tiles
/// of [`TILE`] links: the same arithmetic as [`Group::apply`]'s untiled loops, point by point
/// (each point's F is written once, F ← (F + s_{t−d}) − s_t, or its first or last term
/// alone), with the forces in a sliding window `w`: before tile [j0, j1), `w[..d]` holds
/// s_{j0−d} … s_{j0−1} and the tile writes s_{j0} … s_{j1−1} after them.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn forward_band_tiled<const SET: bool>(
    (start, m, d, uniform): (usize, usize, usize, bool),
    xa: &[f64],
    xb: &[f64],
    xpa: &[f64],
    xpb: &[f64],
    fs: &mut [f64],
    scratch: &mut [f64],
    law: &impl Fn(usize, f64, f64) -> f64,
) {
    let w = &mut scratch[..TILE + d];
    let mut j0 = 0;
    while j0 < m {
        let len = TILE.min(m - j0);
        let (xa, xb) = (&xa[j0..j0 + len], &xb[j0..j0 + len]);
        let (xpa, xpb) = (&xpa[j0..j0 + len], &xpb[j0..j0 + len]);
        band_forces(
            start + j0,
            uniform,
            xa,
            xb,
            xpa,
            xpb,
            &mut w[d..d + len],
            law,
        );
        // Points j0 … j0 + len − 1: the first d of the band only lose s_t.
        let head = d.saturating_sub(j0).min(len);
        let fs_tile = &mut fs[j0..j0 + len];
        for t in 0..head {
            fs_tile[t] = held::<SET>(fs_tile[t]) - w[d + t];
        }
        let (both, before, now) = (&mut fs_tile[head..], &w[head..len], &w[d + head..d + len]);
        for t in 0..both.len() {
            both[t] = (held::<SET>(both[t]) + before[t]) - now[t];
        }
        // The window's last d forces lead the next tile's.
        w.copy_within(len..len + d, 0);
        j0 += len;
    }
    // Points m … m + d − 1 only gain s_{t−d}: the window holds s_{m−d} … s_{m−1}.
    let tail = &mut fs[m..m + d];
    for t in 0..d {
        tail[t] = held::<SET>(tail[t]) + w[t];
    }
}

/// The force a band adds its links' forces to: the point's F, or with `SET` (the band is the
/// first to write it this sample, [`Group::sets`]) the +0 the mass pass used to leave there,
/// without reading F.
#[inline(always)]
fn held<const SET: bool>(f: f64) -> f64 {
    if SET {
        0.0
    } else {
        f
    }
}

/// Adds a forward band's link forces `s` (links j = (q + j, q + j + d), j < m) to its points'
/// forces `fs` (points q … q + m + d − 1): point q + t receives +s_{t−d} (as the second end of
/// link t − d, when d ≤ t < m + d) and then −s_t (as the first end of link t, when t < m), in
/// that order in the list and nothing else within the band, so F ← (F + s_{t−d}) − s_t is the
/// link-by-link scatter's arithmetic exactly.
#[inline(always)]
fn forward_sums<const SET: bool>(fs: &mut [f64], s: &[f64], m: usize, d: usize) {
    let (fs, s) = (&mut fs[..m + d], &s[..m]);
    for t in 0..m.min(d) {
        fs[t] = held::<SET>(fs[t]) - s[t];
    }
    if m > d {
        let (both, s_before, s_now) = (&mut fs[d..m], &s[..m - d], &s[d..m]);
        for t in 0..m - d {
            both[t] = (held::<SET>(both[t]) + s_before[t]) - s_now[t];
        }
    }
    for t in m.max(d)..m + d {
        fs[t] = held::<SET>(fs[t]) + s[t - d];
    }
}

/// [`forward_sums`] of a reversed band (link j = (q + j + d, q + j), q its lower point):
/// point q + t receives −s_{t−d} (first end of link t − d) and then +s_t (second end of link
/// t), in list order: F ← (F − s_{t−d}) + s_t, the scatter's arithmetic.
#[inline(always)]
fn reversed_sums<const SET: bool>(fs: &mut [f64], s: &[f64], m: usize, d: usize) {
    let (fs, s) = (&mut fs[..m + d], &s[..m]);
    for t in 0..m.min(d) {
        fs[t] = held::<SET>(fs[t]) + s[t];
    }
    if m > d {
        let (both, s_before, s_now) = (&mut fs[d..m], &s[..m - d], &s[d..m]);
        for t in 0..m - d {
            both[t] = (held::<SET>(both[t]) - s_before[t]) + s_now[t];
        }
    }
    for t in m.max(d)..m + d {
        fs[t] = held::<SET>(fs[t]) - s[t - d];
    }
}

/// The bands of a link list (endpoints `a`, `b`), in list order: runs of at least
/// [`MIN_CHAIN`] links j = (q + j, q + j + d), or reversed (q + j + d, q + j), as
/// (start, len, d) and whether each is reversed.
pub(crate) fn find_bands(a: &[u32], b: &[u32]) -> (Vec<(u32, u32, u32)>, Vec<bool>) {
    let n = a.len();
    let (mut chains, mut reversed) = (Vec::new(), Vec::new());
    let mut i = 0;
    while i < n {
        // Forward links (q + j, q + j + d), or reversed ones (q + j + d, q + j).
        for (lo, hi, flip) in [(a, b, false), (b, a, true)] {
            let d = hi[i].wrapping_sub(lo[i]);
            let mut end = i;
            while end < n
                && (1..u32::MAX / 2).contains(&d)
                && hi[end].wrapping_sub(lo[end]) == d
                && (end == i || lo[end] == lo[end - 1] + 1)
            {
                end += 1;
            }
            if end - i >= MIN_CHAIN {
                chains.push((i as u32, (end - i) as u32, d));
                reversed.push(flip);
                i = end - 1;
                break;
            }
        }
        i += 1;
    }
    (chains, reversed)
}

/// Links `first..first + a.len()` of a group, one by one: F₁ −= f, F₂ += f.
#[inline(always)]
fn scatter(
    first: usize,
    a: &[u32],
    b: &[u32],
    x: &[f64],
    xp: &[f64],
    f: &mut [f64],
    law: &impl Fn(usize, f64, f64) -> f64,
) {
    let b = &b[..a.len()];
    for k in 0..a.len() {
        let (ia, ib) = (a[k] as usize, b[k] as usize);
        let dx = x[ia] - x[ib];
        let dv = (x[ia] - xp[ia]) - (x[ib] - xp[ib]);
        let force = law(first + k, dx, dv);
        f[ia] -= force;
        f[ib] += force;
    }
}

/// Stage 4: every interaction, one loop per law: the links of law `k` are group
/// `groups[k.index()]`.
#[derive(Clone, Debug, Default)]
pub(crate) struct Interactions {
    pub groups: [Group; LawKind::COUNT],
}

impl Interactions {
    /// The links of one law.
    #[inline(always)]
    pub fn group(&self, kind: LawKind) -> &Group {
        &self.groups[kind.index()]
    }

    /// The links of one law, to change.
    #[cfg(test)]
    pub fn group_mut(&mut self, kind: LawKind) -> &mut Group {
        &mut self.groups[kind.index()]
    }

    /// Every law with its links, in [`LawKind::ALL`] order.
    pub fn by_law(&self) -> impl Iterator<Item = (LawKind, &Group)> {
        LawKind::ALL.into_iter().zip(&self.groups)
    }

    /// Every group, for the compiler's passes.
    pub fn groups_mut(&mut self) -> impl Iterator<Item = &mut Group> {
        self.groups.iter_mut()
    }

    /// Finds the bands that set their points' forces ([`Group::sets`]), done once when the
    /// model is compiled, and returns, per single mass (points `0..singles` of `num_points`),
    /// whether a band sets its force ([`SingleMasses::force_set`](super::masses::SingleMasses)).
    ///
    /// Stage 4 is walked in [`Interactions::step`]'s order, group by group and, within a
    /// group, as [`Group::apply`] runs it: the links before a band one by one, then the band.
    /// A band sets its forces when every point it writes is a single mass (whose F the mass
    /// pass would clear to +0) that nothing before it in stage 4 has written. A mesh's rows
    /// run as one loop, so they set their forces only if every row does. Everything after
    /// the bands in a sample (the later links, the force inputs, the connection points'
    /// spreading) adds to F as before, and the mass pass reads F as before.
    pub fn find_setters(&mut self, singles: usize, num_points: usize) -> Vec<bool> {
        let mut written = vec![false; num_points];
        let mut set = vec![false; singles];
        for g in self.groups_mut() {
            let mut i = 0;
            for c in 0..g.chains.len() {
                let (start, m, _) = g.chains[c];
                g.mark_links(i..start as usize, &mut written);
                g.sets[c] = g.band_points(c).all(|p| p < singles && !written[p]);
                g.band_points(c).for_each(|p| written[p] = true);
                i = (start + m) as usize;
            }
            g.mark_links(i..g.len(), &mut written);
            let mut c = 0;
            while c < g.chains.len() {
                let rows = (g.rows[c] as usize).max(1);
                let all = g.sets[c..c + rows].iter().all(|&s| s);
                g.sets[c..c + rows].fill(all);
                c += rows;
            }
            for c in (0..g.chains.len()).filter(|&c| g.sets[c]) {
                g.band_points(c).for_each(|p| set[p] = true);
            }
        }
        set
    }

    /// [`Group::find_uniform`] for every group.
    pub fn find_uniform(&mut self, args: &[f64]) {
        for g in self.groups_mut() {
            g.find_uniform(args);
        }
    }

    /// Most models use two or three of the laws; an empty one costs one test (its argument
    /// columns are not even sliced). Each law's loop is its own code, its force inlined
    /// ([`LawKind::visit_all`]).
    #[inline(always)]
    pub(crate) fn step(&self, p: &mut Points, args: &[f64]) {
        LawKind::visit_all(&mut Step {
            interactions: self,
            p,
            args,
        });
    }
}

/// Stage 4 on plain numbers, law by law ([`Interactions::step`]). It reads up to five
/// argument columns.
const _: () = assert!(
    LawKind::MAX_ARITY <= 5,
    "Step::visit reads five columns at most"
);

/// Stage 4 on plain numbers, law by law ([`Interactions::step`]).
struct Step<'a> {
    interactions: &'a Interactions,
    p: &'a mut Points,
    args: &'a [f64],
}

impl LawVisitor for Step<'_> {
    #[inline(always)]
    fn visit<L: Law>(&mut self, kind: LawKind) {
        let g = self.interactions.group(kind);
        if g.len() == 0 {
            return;
        }
        // The columns as separate slices (not an array of them): each stays in registers
        // through the loops (an array measured 20 % slower on the 100-mass string).
        let arity = L::ROW.columns.len();
        let col = |c: usize| {
            if c < arity {
                g.col(self.args, c)
            } else {
                &[][..]
            }
        };
        let (c0, c1, c2, c3, c4) = (col(0), col(1), col(2), col(3), col(4));
        g.apply(self.p, |i, dx, dv| {
            L::force(&Scalar, dx, dv, |c| match c {
                0 => c0[i],
                1 => c1[i],
                2 => c2[i],
                3 => c3[i],
                _ => c4[i],
            })
        });
    }
}
