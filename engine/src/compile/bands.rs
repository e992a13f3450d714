//! Pass 4, order into bands (issue 11, point 1): within each interaction group, puts the links
//! that form bands next to each other, whatever order the script wrote them in.
//!
//! The engine runs a band — links j = (q + j, q + j + d) over a contiguous point range, or
//! the reverse (q + j + d, q + j) — as two contiguous loops instead of a gather and scatter
//! ([`crate::sim::kernels::links::Group::apply`]), but it finds bands in list order only. A script
//! that writes a mesh's row link, column link, row link… or a `~generate triangle`, `hexagon`
//! or `lattice`, or a MIMS4Max export, interleaves its bands. This pass sorts each group's links
//! by (direction, d, first point), cuts the sorted list into runs of consecutive first points,
//! keeps the runs of at least [`MIN_CHAIN`] links as bands and leaves every other link after
//! them, in script order.
//!
//! Spec §1.5 (normative) fixes what each stage computes; the order of stage 4's interactions
//! "determines only the floating-point summation order into the F accumulators". A group is
//! reordered unless the script's order already bands every link (strings and meshes written
//! row by row keep their order and their exact bits) or the sorted order bands fewer. Equal
//! counts still reorder: bands sorted by d run faster than bands in the script's interleaving
//! (`~generate triangle size=30`: 1,287 of 1,305 links banded either way, 1,400 → 1,125 ns).

use super::kinds::{LinkGroups, Row};
use crate::laws::LawKind;
use crate::sim::kernels::links::{find_bands, MIN_CHAIN};

/// How many of a link list's links the engine runs in bands.
fn banded(a: &[u32], b: &[u32]) -> usize {
    find_bands(a, b).0.iter().map(|c| c.1 as usize).sum()
}

/// The band order of a link list: the positions of the links, bands first (by direction, d,
/// then first point), then every other link in list order; and, per position, whether the
/// link is to be turned round (`odd` laws only: a band is then one direction, whichever way
/// its links were written).
fn band_order(a: &[u32], b: &[u32], odd: bool) -> (Vec<usize>, Vec<bool>) {
    // (reversed, d, first point) of every link that can be in a band.
    let key = |i: usize| match a[i].cmp(&b[i]) {
        std::cmp::Ordering::Less => Some((false, b[i] - a[i], a[i])),
        std::cmp::Ordering::Greater => Some((!odd, a[i] - b[i], b[i])),
        std::cmp::Ordering::Equal => None,
    };
    let mut sorted: Vec<(bool, u32, u32, usize)> = (0..a.len())
        .filter_map(|i| key(i).map(|(r, d, q)| (r, d, q, i)))
        .collect();
    sorted.sort_unstable();
    let mut bands = Vec::with_capacity(a.len());
    let mut in_band = vec![false; a.len()];
    let mut run: Vec<usize> = Vec::new();
    let mut close = |run: &mut Vec<usize>, bands: &mut Vec<usize>| {
        if run.len() >= MIN_CHAIN {
            for &i in run.iter() {
                in_band[i] = true;
            }
            bands.extend_from_slice(run);
        }
        run.clear();
    };
    let mut last: Option<(bool, u32, u32)> = None;
    for &(r, d, q, i) in &sorted {
        match last {
            // A second link on the same two points stays out of the band.
            Some(l) if l == (r, d, q) => continue,
            Some((lr, ld, lq)) if lr == r && ld == d && lq + 1 == q => {}
            _ => close(&mut run, &mut bands),
        }
        run.push(i);
        last = Some((r, d, q));
    }
    close(&mut run, &mut bands);
    let flip: Vec<bool> = (0..a.len())
        .map(|i| in_band[i] && odd && a[i] > b[i])
        .collect();
    let rest = (0..a.len()).filter(|&i| !in_band[i]);
    bands.extend(rest);
    (bands, flip)
}

impl LinkGroups<'_> {
    /// Reorders each group into bands, unless its links are all banded as written or the
    /// sorted order bands fewer (see the module's documentation).
    pub fn order_into_bands(&mut self) {
        for (rows, kind) in self.groups.iter_mut().zip(LawKind::ALL) {
            let odd = kind.row().odd;
            let n = rows.len();
            if n < MIN_CHAIN {
                continue;
            }
            let a: Vec<u32> = rows.iter().map(|r| r.a).collect();
            let b: Vec<u32> = rows.iter().map(|r| r.b).collect();
            let as_written = banded(&a, &b);
            if as_written == n {
                continue;
            }
            let (order, flip) = band_order(&a, &b, odd);
            let turn = |i: usize| if flip[i] { (b[i], a[i]) } else { (a[i], b[i]) };
            let (sa, sb): (Vec<u32>, Vec<u32>) = order.iter().map(|&i| turn(i)).unzip();
            if banded(&sa, &sb) >= as_written {
                let mut taken: Vec<Option<Row>> = rows.drain(..).map(Some).collect();
                rows.extend(order.iter().map(|&i| {
                    let mut row = taken[i].take().expect("a permutation");
                    if flip[i] {
                        std::mem::swap(&mut row.a, &mut row.b);
                    }
                    row
                }));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn links(pairs: &[(u32, u32)]) -> (Vec<u32>, Vec<u32>) {
        pairs.iter().copied().unzip()
    }

    #[test]
    fn interleaved_bands_come_out_banded() {
        // A 3 × 6 mesh (width 6) written node by node: right link, then down link.
        let w = 6;
        let mut pairs = Vec::new();
        for r in 0..3 {
            for c in 0..w {
                let p = r * w + c;
                if c + 1 < w {
                    pairs.push((p, p + 1));
                }
                if r + 1 < 3 {
                    pairs.push((p, p + w));
                }
            }
        }
        let (a, b) = links(&pairs);
        // As written, only the last row (right links alone) is a band.
        assert_eq!(banded(&a, &b), 5);
        let (order, _) = band_order(&a, &b, false);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(
            sorted,
            (0..pairs.len()).collect::<Vec<_>>(),
            "a permutation"
        );
        let (sa, sb): (Vec<u32>, Vec<u32>) = order.iter().map(|&i| (a[i], b[i])).unzip();
        // Rows: 3 bands of 5 links; columns: one band of 12 links (d = 6).
        assert_eq!(banded(&sa, &sb), pairs.len());
    }

    #[test]
    fn reversed_duplicate_and_short_runs_keep_their_places() {
        // A reversed band of 4, a duplicate of its second link, a self-link and a run of 2.
        let pairs = [
            (9, 8),
            (20, 30),
            (5, 5),
            (10, 9),
            (10, 9),
            (11, 10),
            (21, 31),
            (12, 11),
        ];
        let (a, b) = links(&pairs);
        let (order, flip) = band_order(&a, &b, false);
        assert_eq!(order, vec![0, 3, 5, 7, 1, 2, 4, 6]);
        assert!(flip.iter().all(|f| !f));
        let (sa, sb): (Vec<u32>, Vec<u32>) = order.iter().map(|&i| (a[i], b[i])).unzip();
        let (chains, reversed) = find_bands(&sa, &sb);
        assert_eq!(chains, vec![(0, 4, 1)]);
        assert_eq!(reversed, vec![true]);
    }

    #[test]
    fn links_of_odd_laws_are_turned_round_into_one_band() {
        // Six links of one band, written either way round.
        let pairs = [(1, 2), (3, 2), (3, 4), (5, 4), (5, 6), (6, 7)];
        let (a, b) = links(&pairs);
        let (order, flip) = band_order(&a, &b, true);
        assert_eq!(order, vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(flip, vec![false, true, false, true, false, false]);
        // A law that is not odd keeps each link's direction: no band of four either way.
        let (_, flip) = band_order(&a, &b, false);
        assert!(flip.iter().all(|f| !f));
    }
}
