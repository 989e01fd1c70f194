//! Passes over the cells in lanes: the small helpers the scheme's passes are made of, and the
//! sums and surveys of a substep, written so that every build (baseline, AVX2, AVX-512F)
//! vectorises them and gives the same bits. A sum or a minimum taken in order is a chain of
//! dependent operations as long as the channel (3-4 cycles each) and is not vectorised;
//! element i goes into lane i mod W instead, and the lanes are combined in a fixed order.

/// Width of the chunks the passes over the cells and the interfaces run in: a whole number of
/// vectors of every build (8 AVX-512F lanes, 2 AVX2 vectors, 4 SSE2 ones), and the number of
/// lanes of the sums.
pub const W: usize = 8;

/// The smaller and the larger of two numbers, one instruction each (f64::min and max take
/// seven, for NaN). A NaN anywhere in the state is refused at the end of the substep, so
/// these need not handle it; whichever number they return then, the step is refused.
#[inline(always)]
pub fn smaller(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

#[inline(always)]
pub fn larger(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// The larger of a speed met so far and a new one; a NaN new one is passed over, as
/// f64::max does.
#[inline(always)]
pub fn faster(speed: f64, new: f64) -> f64 {
    if new > speed { new } else { speed }
}

/// 0..len as one range of a whole number of chunks of W and, if len is not a multiple of W,
/// the last W elements again (overlapping the first range, whose elements there it computes
/// again from the same inputs, to the same bits); below W elements, 0..len; for none, no range
/// (a pass over the interior cells of one cell must not read its neighbours). A loop over each
/// then runs whole vectors only, no scalar remainder (at 200 cells, the remainders of the
/// face and flux passes cost about as much as three chunks of eight).
pub fn whole_chunks(len: usize) -> impl Iterator<Item = std::ops::Range<usize>> {
    let rest = len % W;
    // None for no elements; below W elements, or a whole number of chunks, one range.
    let (first, tail) = if len == 0 {
        (None, None)
    } else if len < W || rest == 0 {
        (Some(0..len), None)
    } else {
        (Some(0..len - rest), Some(len - W..len))
    };
    first.into_iter().chain(tail)
}

/// The lanes' partial sums, added pairwise in a fixed order.
#[inline(always)]
fn total([a, b, c, d, e, f, g, h]: [f64; W]) -> f64 {
    ((a + e) + (c + g)) + ((b + f) + (d + h))
}

/// The sum of `x` in W lanes, element i into lane i mod W, the lanes then added pairwise in a
/// fixed order: the same operations on every build, so the same bits.
#[inline(always)]
pub fn lane_sum(x: &[f64]) -> f64 {
    let (chunks, rest) = x.as_chunks::<W>();
    let mut lanes = [0.0; W];
    for c in chunks {
        for (l, &x) in lanes.iter_mut().zip(c) {
            *l += x;
        }
    }
    for (l, &x) in lanes.iter_mut().zip(rest) {
        *l += x;
    }
    total(lanes)
}

/// The sum of `term(i)` for i in 0..n, in lanes as [`lane_sum`] (the same bits as
/// [`lane_sum`] of the terms).
#[inline(always)]
pub fn lane_sum_by(n: usize, term: impl Fn(usize) -> f64) -> f64 {
    let mut lanes = [0.0; W];
    let whole = n - n % W;
    for k in (0..whole).step_by(W) {
        for (j, l) in lanes.iter_mut().enumerate() {
            *l += term(k + j);
        }
    }
    for (j, l) in lanes.iter_mut().enumerate().take(n - whole) {
        *l += term(whole + j);
    }
    total(lanes)
}

/// `q` times `decay` into `out`, and the sum of `q` (as [`lane_sum`]): one pass.
#[inline(always)]
pub fn decayed(q: &[f64], out: &mut [f64], decay: f64) -> f64 {
    let (chunks, rest) = q.as_chunks::<W>();
    let (outs, out_rest) = out[..q.len()].as_chunks_mut::<W>();
    let mut lanes = [0.0; W];
    for (c, o) in chunks.iter().zip(outs) {
        for ((l, &q), o) in lanes.iter_mut().zip(c).zip(o) {
            *l += q;
            *o = q * decay;
        }
    }
    for ((l, &q), o) in lanes.iter_mut().zip(rest).zip(out_rest) {
        *l += q;
        *o = q * decay;
    }
    total(lanes)
}

/// What the end of a substep needs of its new state: see [`survey`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Survey {
    /// The smallest depth (a NaN passed over).
    pub shallowest: f64,
    /// Whether every depth and discharge is finite.
    pub finite: bool,
}

/// The smallest of the depths `h` and whether all of them and of the discharges `q` are
/// finite: one pass.
#[inline(always)]
pub fn survey(h: &[f64], q: &[f64]) -> Survey {
    let (hs, h_rest) = h.as_chunks::<W>();
    let (qs, q_rest) = q[..h.len()].as_chunks::<W>();
    let mut low = [f64::INFINITY; W];
    // 0 x is (+-)0 for a finite x and NaN for an infinite or NaN one: a sum of them is 0
    // only if all are finite.
    let mut probe = [0.0; W];
    let mut lane = |j: usize, h: f64, q: f64| {
        probe[j] += 0.0 * h + 0.0 * q;
        low[j] = smaller(h, low[j]);
    };
    for (h, q) in hs.iter().zip(qs) {
        for (j, (&h, &q)) in h.iter().zip(q).enumerate() {
            lane(j, h, q);
        }
    }
    for (j, (&h, &q)) in h_rest.iter().zip(q_rest).enumerate() {
        lane(j, h, q);
    }
    Survey {
        shallowest: low.into_iter().fold(f64::INFINITY, smaller),
        finite: total(probe) == 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers of mixed signs and sizes, none summing exactly.
    fn numbers(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| ((i as f64 + 0.3) * 1.7).sin() * 10f64.powi(i as i32 % 5 - 2))
            .collect()
    }

    /// The sum in lanes, written out: element i into lane i mod 8.
    fn by_hand(x: &[f64]) -> f64 {
        let mut lanes = [0.0; W];
        for (i, &x) in x.iter().enumerate() {
            lanes[i % W] += x;
        }
        let [a, b, c, d, e, f, g, h] = lanes;
        ((a + e) + (c + g)) + ((b + f) + (d + h))
    }

    #[test]
    fn sums_are_the_lane_sum_written_out() {
        for n in 0..40 {
            let x = numbers(n);
            let expected = by_hand(&x).to_bits();
            assert_eq!(lane_sum(&x).to_bits(), expected, "lane_sum, {n}");
            assert_eq!(
                lane_sum_by(n, |i| x[i]).to_bits(),
                expected,
                "lane_sum_by, {n}"
            );
            // ... and they are sums: within rounding of the sum in order.
            let plain: f64 = x.iter().sum();
            let scale: f64 = x.iter().map(|x| x.abs()).sum();
            assert!((lane_sum(&x) - plain).abs() <= 1e-15 * scale, "{n}");
            let mut out = vec![7.0; n + 3];
            let sum = decayed(&x, &mut out, 0.75);
            assert_eq!(sum.to_bits(), expected, "decayed, {n}");
            for (i, (&o, &x)) in out.iter().zip(&x).enumerate() {
                assert_eq!(o, 0.75 * x, "decayed, element {i} of {n}");
            }
            assert!(out[n..].iter().all(|&o| o == 7.0), "decayed writes past q");
        }
    }

    #[test]
    fn survey_finds_the_shallowest_and_anything_not_finite() {
        for n in 1..40 {
            let h: Vec<f64> = numbers(n).iter().map(|x| 1.0 + x).collect();
            let q = numbers(n + 1)[1..].to_vec();
            let s = survey(&h, &q);
            let lowest = h.iter().copied().fold(f64::INFINITY, f64::min);
            assert_eq!(s.shallowest, lowest, "{n}");
            assert!(s.finite, "{n}");
            // A non-finite value anywhere, in either, is found; a NaN depth is not the lowest.
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for i in 0..n {
                    let (mut hb, mut qb) = (h.clone(), q.clone());
                    hb[i] = bad;
                    let s = survey(&hb, &q);
                    assert!(!s.finite, "depth {bad} at {i} of {n}");
                    if bad.is_nan() {
                        let rest = hb.iter().filter(|h| !h.is_nan());
                        assert_eq!(s.shallowest, rest.copied().fold(f64::INFINITY, f64::min));
                    }
                    qb[i] = bad;
                    assert!(!survey(&h, &qb).finite, "discharge {bad} at {i} of {n}");
                }
            }
        }
    }

    #[test]
    fn whole_chunks_cover_each_element_in_whole_vectors() {
        for len in 0..40 {
            let parts: Vec<_> = whole_chunks(len).collect();
            let mut seen = vec![0; len];
            for p in &parts {
                assert!(p.end <= len);
                assert!(len < W || p.len() % W == 0, "{len}: {p:?}");
                seen[p.clone()].iter_mut().for_each(|s| *s += 1);
            }
            assert!(seen.iter().all(|&s| s >= 1), "{len}: {parts:?}");
            assert_eq!(parts.is_empty(), len == 0);
        }
    }

    #[test]
    fn smaller_larger_faster() {
        assert_eq!((smaller(1.0, 2.0), smaller(2.0, 1.0)), (1.0, 1.0));
        assert_eq!((larger(1.0, 2.0), larger(2.0, 1.0)), (2.0, 2.0));
        assert_eq!((faster(1.0, 2.0), faster(2.0, 1.0)), (2.0, 2.0));
        assert_eq!(faster(1.0, f64::NAN), 1.0);
    }
}
