//! Tiny slice kernels used in the projections (no allocation).

#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[inline]
pub fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

#[inline]
pub fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

/// Solves the small dense system `M x = r` (row-major `k x k`) by Gaussian elimination with
/// partial pivoting, in place. Returns `false` when a pivot is below `tol * max|M|`.
pub fn solve_small(m: &mut [f64], r: &mut [f64], k: usize, tol: f64) -> bool {
    let scale = m.iter().fold(0.0f64, |a, &b| a.max(b.abs())).max(f64::MIN_POSITIVE);
    for col in 0..k {
        let (piv, pmax) =
            (col..k).map(|i| (i, m[i * k + col].abs())).fold((col, -1.0), |a, b| if b.1 > a.1 { b } else { a });
        if pmax <= tol * scale {
            return false;
        }
        if piv != col {
            for j in 0..k {
                m.swap(col * k + j, piv * k + j);
            }
            r.swap(col, piv);
        }
        for i in col + 1..k {
            let f = m[i * k + col] / m[col * k + col];
            if f != 0.0 {
                for j in col..k {
                    m[i * k + j] -= f * m[col * k + j];
                }
                r[i] -= f * r[col];
            }
        }
    }
    for i in (0..k).rev() {
        let mut s = r[i];
        for j in i + 1..k {
            s -= m[i * k + j] * r[j];
        }
        r[i] = s / m[i * k + i];
    }
    true
}

/// Iterates over all subsets of `0..k` of size `size` in lexicographic order.
pub fn for_each_subset(k: usize, size: usize, mut f: impl FnMut(&[usize]) -> bool) {
    if size > k {
        return;
    }
    let mut idx: Vec<usize> = (0..size).collect();
    loop {
        if !f(&idx) {
            return;
        }
        // advance
        let mut i = size;
        loop {
            if i == 0 {
                return;
            }
            i -= 1;
            if idx[i] < k - size + i {
                idx[i] += 1;
                for j in i + 1..size {
                    idx[j] = idx[j - 1] + 1;
                }
                break;
            }
            if i == 0 {
                return;
            }
        }
    }
}

/// Orthonormal basis (Gram-Schmidt, twice) of the orthogonal complement of the span of
/// `vectors` in R^p. Returned as a list of vectors.
pub fn orthogonal_complement(vectors: &[Vec<f64>], p: usize) -> Vec<Vec<f64>> {
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let add = |v: &mut Vec<f64>, basis: &mut Vec<Vec<f64>>| {
        for _ in 0..2 {
            for b in basis.iter() {
                let c = dot(v, b);
                v.iter_mut().zip(b).for_each(|(x, y)| *x -= c * y);
            }
        }
        let n = norm(v);
        if n > 1e-10 {
            v.iter_mut().for_each(|x| *x /= n);
            basis.push(v.clone());
            true
        } else {
            false
        }
    };
    for v in vectors {
        let mut v = v.clone();
        let s = norm(&v).max(f64::MIN_POSITIVE);
        v.iter_mut().for_each(|x| *x /= s);
        add(&mut v, &mut basis);
    }
    let span_dim = basis.len();
    for i in 0..p {
        let mut e = vec![0.0; p];
        e[i] = 1.0;
        add(&mut e, &mut basis);
    }
    basis.split_off(span_dim)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subsets_are_enumerated() {
        let mut all = Vec::new();
        for_each_subset(4, 2, |s| {
            all.push(s.to_vec());
            true
        });
        assert_eq!(all, vec![vec![0, 1], vec![0, 2], vec![0, 3], vec![1, 2], vec![1, 3], vec![2, 3]]);
        let mut n = 0;
        for_each_subset(3, 3, |_| {
            n += 1;
            true
        });
        assert_eq!(n, 1);
    }

    #[test]
    fn small_solve_matches_hand_solution() {
        let mut m = vec![2.0, 1.0, 1.0, 3.0];
        let mut r = vec![3.0, 5.0];
        assert!(solve_small(&mut m, &mut r, 2, 1e-14));
        assert!((r[0] - 0.8).abs() < 1e-15 && (r[1] - 1.4).abs() < 1e-15);
        let mut s = vec![1.0, 2.0, 2.0, 4.0];
        let mut r2 = vec![1.0, 1.0];
        assert!(!solve_small(&mut s, &mut r2, 2, 1e-12), "singular system must be reported");
    }

    #[test]
    fn complement_is_orthonormal_and_orthogonal() {
        let c = orthogonal_complement(&[vec![1.0, 1.0, 0.0]], 3);
        assert_eq!(c.len(), 2);
        for b in &c {
            assert!((norm(b) - 1.0).abs() < 1e-14);
            assert!(dot(b, &[1.0, 1.0, 0.0]).abs() < 1e-14);
        }
        assert!(dot(&c[0], &c[1]).abs() < 1e-14);
    }
}
