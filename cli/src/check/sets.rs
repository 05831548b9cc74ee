//! Which shader-def sets to check: every combination of the factors when there are at most N,
//! else a covering set of every pair of factor levels (pairwise) plus each def alone and the
//! default. A factor is what varies: one def on or off, a valued def's values, a `one_of`
//! group's members.

use std::collections::BTreeSet;

use lodkit::shaders::ShaderDefValue;

/// One thing that varies between sets; each level is the defs it sets (empty: none).
#[derive(Clone, Debug)]
pub struct Factor {
    /// Each level's defs.
    pub levels: Vec<Vec<(String, ShaderDefValue)>>,
}

/// How the sets were chosen, for the report.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// Every combination (the number of combinations before constraints).
    All(u128),
    /// Pairwise: `pairs` level pairs covered, `infeasible` excluded by constraints, out of
    /// `total` combinations.
    Pairwise {
        /// Combinations there are.
        total: u128,
        /// Level pairs covered.
        pairs: usize,
        /// Level pairs no allowed set has.
        infeasible: usize,
    },
}

/// Whether a set of defs may be checked.
pub type Allowed<'a> = dyn Fn(&[(String, ShaderDefValue)]) -> bool + 'a;

/// A row: the level of each factor.
pub type Row = Vec<usize>;

/// The defs of `row`.
pub fn defs_of(factors: &[Factor], row: &Row) -> Vec<(String, ShaderDefValue)> {
    factors
        .iter()
        .zip(row)
        .flat_map(|(f, &l)| f.levels[l].iter().cloned())
        .collect()
}

/// Small deterministic generator (splitmix64): the same factors give the same sets every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

type Pair = (usize, usize, usize, usize);

/// The sets to check, and how they were chosen. `allowed` says whether a set of defs may be
/// checked (the `requires` and `excludes` of a permutation file).
pub fn choose(factors: &[Factor], max_sets: usize, allowed: &Allowed) -> (Vec<Row>, Coverage) {
    let total = factors
        .iter()
        .fold(1u128, |n, f| n.saturating_mul(f.levels.len() as u128));
    let ok = |row: &Row| allowed(&defs_of(factors, row));
    if total <= max_sets as u128 {
        let mut rows = Vec::new();
        let mut row = vec![0; factors.len()];
        loop {
            if ok(&row) {
                rows.push(row.clone());
            }
            // Mixed-radix increment, the last factor fastest.
            let mut i = factors.len();
            loop {
                if i == 0 {
                    return (rows, Coverage::All(total));
                }
                i -= 1;
                row[i] += 1;
                if row[i] < factors[i].levels.len() {
                    break;
                }
                row[i] = 0;
            }
        }
    }
    let mut rows: Vec<Row> = Vec::new();
    let push = |rows: &mut Vec<Row>, row: Row| {
        if ok(&row) && !rows.contains(&row) {
            rows.push(row);
        }
    };
    // The default, then each def alone.
    push(&mut rows, vec![0; factors.len()]);
    for (f, factor) in factors.iter().enumerate() {
        for l in 1..factor.levels.len() {
            let mut row = vec![0; factors.len()];
            row[f] = l;
            push(&mut rows, row);
        }
    }
    let mut uncovered: BTreeSet<Pair> = BTreeSet::new();
    for a in 0..factors.len() {
        for b in a + 1..factors.len() {
            for la in 0..factors[a].levels.len() {
                for lb in 0..factors[b].levels.len() {
                    uncovered.insert((a, la, b, lb));
                }
            }
        }
    }
    let all_pairs = uncovered.len();
    let covers = |row: &Row, p: &Pair| row[p.0] == p.1 && row[p.2] == p.3;
    for row in &rows {
        uncovered.retain(|p| !covers(row, p));
    }
    let mut rng = Rng(0x1f2e_3d4c_5b6a_7988);
    let mut infeasible = 0;
    while let Some(&first) = uncovered.iter().next() {
        let mut best: Option<(usize, Row)> = None;
        for _ in 0..24 {
            // Start from an uncovered pair, fill the other factors greedily in a random order.
            let seed = *uncovered
                .iter()
                .nth(rng.below(uncovered.len()))
                .unwrap_or(&first);
            if let Some(row) = build_row(factors, &uncovered, seed, &mut rng, &ok, true) {
                let score = uncovered.iter().filter(|p| covers(&row, p)).count();
                if best.as_ref().is_none_or(|(s, _)| score > *s) {
                    best = Some((score, row));
                }
            }
        }
        match best {
            Some((score, row)) if score > 0 => {
                uncovered.retain(|p| !covers(&row, p));
                rows.push(row);
            }
            _ => {
                // Try the first pair alone, harder; no allowed set has it when all tries fail.
                let found = (0..200)
                    .find_map(|_| build_row(factors, &uncovered, first, &mut rng, &ok, false));
                match found {
                    Some(row) => {
                        uncovered.retain(|p| !covers(&row, p));
                        rows.push(row);
                    }
                    None => {
                        uncovered.remove(&first);
                        infeasible += 1;
                    }
                }
            }
        }
    }
    (
        rows,
        Coverage::Pairwise {
            total,
            pairs: all_pairs - infeasible,
            infeasible,
        },
    )
}

/// A row holding the levels of `seed`, the other factors chosen to cover the most uncovered
/// pairs with those chosen before them (or at random when not `greedy`); `None` when the row
/// is not allowed.
fn build_row(
    factors: &[Factor],
    uncovered: &BTreeSet<Pair>,
    seed: Pair,
    rng: &mut Rng,
    ok: &dyn Fn(&Row) -> bool,
    greedy: bool,
) -> Option<Row> {
    let n = factors.len();
    let mut row: Vec<Option<usize>> = vec![None; n];
    row[seed.0] = Some(seed.1);
    row[seed.2] = Some(seed.3);
    let mut order: Vec<usize> = (0..n).filter(|&f| row[f].is_none()).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.below(i + 1));
    }
    for f in order {
        let gain = |l: usize| {
            (0..n)
                .filter_map(|g| row[g].map(|lg| (g, lg)))
                .filter(|&(g, lg)| {
                    let p = if g < f { (g, lg, f, l) } else { (f, l, g, lg) };
                    uncovered.contains(&p)
                })
                .count()
        };
        let levels = factors[f].levels.len();
        let start = rng.below(levels);
        if !greedy {
            row[f] = Some(start);
            continue;
        }
        // The level that covers the most, among those the row (the rest at level 0) allows.
        let allows = |l: usize| {
            let mut partial: Row = row.iter().map(|x| x.unwrap_or(0)).collect();
            partial[f] = l;
            ok(&partial)
        };
        let best = (0..levels)
            .map(|k| (start + k) % levels)
            .max_by_key(|&l| (allows(l), gain(l)))
            .unwrap_or(0);
        row[f] = Some(best);
    }
    let row: Row = row.into_iter().map(|l| l.unwrap_or(0)).collect();
    ok(&row).then_some(row)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flags(n: usize) -> Vec<Factor> {
        (0..n)
            .map(|i| Factor {
                levels: vec![vec![], vec![(format!("D{i}"), ShaderDefValue::Bool(true))]],
            })
            .collect()
    }

    #[test]
    fn all_combinations_up_to_the_limit() {
        let (rows, coverage) = choose(&flags(3), 8, &|_| true);
        assert_eq!(rows.len(), 8);
        assert_eq!(coverage, Coverage::All(8));
    }

    #[test]
    fn pairwise_covers_every_pair_with_few_sets() {
        let factors = flags(10);
        let (rows, coverage) = choose(&factors, 256, &|_| true);
        // 1024 combinations: pairwise, every one of the 45 * 4 level pairs in some row.
        assert_eq!(
            coverage,
            Coverage::Pairwise {
                total: 1024,
                pairs: 180,
                infeasible: 0
            }
        );
        for a in 0..10 {
            for b in a + 1..10 {
                for (la, lb) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                    assert!(rows.iter().any(|r| r[a] == la && r[b] == lb));
                }
            }
        }
        // The default and each def alone (11 rows) plus a handful of covering rows.
        assert!(rows.len() <= 11 + 10, "{}", rows.len());
    }

    #[test]
    fn constraints_remove_pairs_no_allowed_set_has() {
        // D0 excludes D1: the pair (D0 on, D1 on) is infeasible.
        let factors = flags(9);
        let allowed = |defs: &[(String, ShaderDefValue)]| {
            !(defs.iter().any(|d| d.0 == "D0") && defs.iter().any(|d| d.0 == "D1"))
        };
        let (rows, coverage) = choose(&factors, 256, &allowed);
        assert!(
            matches!(coverage, Coverage::Pairwise { infeasible: 1, .. }),
            "{coverage:?}"
        );
        assert!(rows.iter().all(|r| !(r[0] == 1 && r[1] == 1)));
    }
}
