//! The log marginal likelihood of a (warped-input) GP and its gradient,
//! evaluated in buffers kept between calls: an optimiser start calls it
//! hundreds of times on the same n, and fresh n×n matrices each time cost
//! as much in page faults as the arithmetic. Lower triangles only, column
//! by column (contiguous in faer's column-major storage).
//!
//! ∂L/∂θ_j = ½ tr(W ∂K/∂θ_j), W = Σ_c α_c α_cᵀ − m K⁻¹ (Rasmussen and
//! Williams 2006, eq. 5.9). With u = Σ_k t_k² / l_k², t_k = w_ik − w_jk and
//! k = s² g(u): ∂K_ij/∂ln l_k = s² h t_k² / l_k², ∂K_ij/∂λ_k =
//! −s² h t_k (∂w_ik/∂λ_k − ∂w_jk/∂λ_k) / l_k² (h = −2 g'(u)).

use super::error::GpError;
use super::kernel::{self, Kernel, KernelKind};
use super::likelihood::JITTERS;
use super::warp::InputWarp;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::{Mat, Par};

/// Buffers of one evaluation, reused while n stays the same.
pub struct LmlWorkspace {
    /// K = s² g + σ² I (lower triangle).
    k: Mat<f64>,
    /// h = −2 g'(u) (lower triangle; empty for the squared exponential, whose h is g).
    h: Mat<f64>,
    /// ∂g/∂ln α (lower triangle; rational quadratic only).
    da: Mat<f64>,
    /// Cholesky factor L of K + jitter.
    l: Mat<f64>,
    /// K⁻¹ (lower triangle).
    kinv: Mat<f64>,
    /// Scratch of the factorisation, solves and inverse.
    buf: Option<MemBuffer>,
}

impl Default for LmlWorkspace {
    fn default() -> Self {
        let e = || Mat::zeros(0, 0);
        LmlWorkspace { k: e(), h: e(), da: e(), l: e(), kinv: e(), buf: None }
    }
}

impl LmlWorkspace {
    /// Σ_c log marginal likelihood of the outputs `ys` and its gradient in θ
    /// = [kernel θ.., λ.. (one per warped input), ln σ²]; `ratios` marks the
    /// warped inputs (empty: none); `x` is (n, d) row-major.
    pub fn lml_and_grad(
        &mut self,
        kind: KernelKind,
        ratios: &[Option<f64>],
        theta: &[f64],
        x: &[f64],
        d: usize,
        ys: &[&[f64]],
    ) -> Result<(f64, Vec<f64>), GpError> {
        let np = theta.len() - 1;
        let nk = np - ratios.iter().filter(|r| r.is_some()).count();
        let kernel = Kernel::from_log(kind, &theta[..nk]);
        let warp = InputWarp::from_parts(ratios, &theta[nk..np]);
        let (xw, dw) = warp.apply_with_grad(x, d);
        let n = ys[0].len();
        let cols = Columns::new(&xw, &dw, d, n);
        let noise_var = theta[np].exp();
        self.resize(n, kind);
        self.fill_pairs(&kernel, &cols, noise_var);
        self.factor(kernel.variance)?;
        let (value, alphas) = self.value_and_weights(ys);
        self.invert();
        let mut grad = vec![0.0; theta.len()];
        let slots = warp_slots(ratios, d, nk);
        let trace_w = self.accumulate_gradient(&kernel, &cols, &slots, &alphas, &mut grad);
        grad[d] += 0.5 * kernel.variance * trace_w;
        grad[np] = 0.5 * noise_var * trace_w;
        Ok((value, grad))
    }

    /// Sizes the buffers for n points (kept when n is unchanged).
    fn resize(&mut self, n: usize, kind: KernelKind) {
        let fit = |m: &mut Mat<f64>, want: bool| {
            let size = if want { n } else { 0 };
            if m.nrows() != size {
                *m = Mat::zeros(size, size);
            }
        };
        fit(&mut self.k, true);
        fit(&mut self.h, kind != KernelKind::SquaredExponential);
        fit(&mut self.da, kind == KernelKind::RationalQuadratic);
        fit(&mut self.l, true);
        fit(&mut self.kinv, true);
        let req = StackReq::any_of(&[
            llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default()),
            llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq),
            llt::inverse::inverse_scratch::<f64>(n, Par::Seq),
        ]);
        if self.buf.as_ref().is_none_or(|b| b.len() < req.unaligned_bytes_required()) {
            self.buf = Some(MemBuffer::new(req));
        }
    }

    /// Lower triangles of K, h and ∂g/∂ln α (compiled for the widest SIMD
    /// the CPU offers, chosen at run time).
    fn fill_pairs(&mut self, kernel: &Kernel, x: &Columns, noise_var: f64) {
        pulp::Arch::new().dispatch(FillPairs { ws: self, kernel, x, noise_var })
    }

    #[inline(always)]
    fn fill_pairs_body(&mut self, kernel: &Kernel, x: &Columns, noise_var: f64) {
        let n = x.n;
        let s2 = kernel.variance;
        let (keep_h, keep_da) = (self.h.nrows() == n, self.da.nrows() == n);
        let mut u = vec![0.0; n];
        for j in 0..n {
            let u = &mut u[j + 1..];
            u.fill(0.0);
            for (k, l) in kernel.lengths.iter().enumerate() {
                let (xj, inv_l) = (x.col(k)[j], 1.0 / l);
                for (v, xi) in u.iter_mut().zip(&x.col(k)[j + 1..]) {
                    let t = (xi - xj) * inv_l;
                    *v += t * t;
                }
            }
            self.k[(j, j)] = s2 + noise_var;
            let k_j = &mut lower_from_mut(&mut self.k, j)[1..];
            let h_j = keep_h.then(|| &mut lower_from_mut(&mut self.h, j)[1..]);
            let da_j = keep_da.then(|| &mut lower_from_mut(&mut self.da, j)[1..]);
            match kernel.kind {
                KernelKind::SquaredExponential => {
                    shape_column(u, s2, k_j, h_j, da_j, kernel::squared_exponential)
                }
                KernelKind::Matern32 => shape_column(u, s2, k_j, h_j, da_j, kernel::matern32),
                KernelKind::Matern52 => shape_column(u, s2, k_j, h_j, da_j, kernel::matern52),
                KernelKind::RationalQuadratic => shape_column(u, s2, k_j, h_j, da_j, |v| {
                    kernel::rational_quadratic(kernel.alpha, v)
                }),
            }
        }
    }

    /// L of K + jitter, escalating the jitter (relative to `scale`) on failure.
    fn factor(&mut self, scale: f64) -> Result<(), GpError> {
        let n = self.k.nrows();
        let buf = self.buf.as_mut().expect("sized by resize");
        for rel in JITTERS {
            for j in 0..n {
                let dst =
                    self.l.col_mut(j).try_as_col_major_mut().expect("faer columns are contiguous");
                dst.as_slice_mut()[j..].copy_from_slice(lower_from(&self.k, j));
            }
            for j in 0..n {
                self.l[(j, j)] += rel * scale;
            }
            let ok = llt::factor::cholesky_in_place(
                self.l.as_mut(),
                Default::default(),
                Par::Seq,
                MemStack::new(buf),
                Default::default(),
            );
            if ok.is_ok() {
                return Ok(());
            }
        }
        Err(GpError::NotPositiveDefinite { jitter: JITTERS[JITTERS.len() - 1] * scale, n })
    }

    /// α_c = K⁻¹ y_c.
    fn solve(&mut self, y: &[f64]) -> Vec<f64> {
        let mut rhs = Mat::<f64>::from_fn(y.len(), 1, |i, _| y[i]);
        let buf = self.buf.as_mut().expect("sized by resize");
        llt::solve::solve_in_place(self.l.as_ref(), rhs.as_mut(), Par::Seq, MemStack::new(buf));
        (0..y.len()).map(|i| rhs[(i, 0)]).collect()
    }

    /// Σ_c (−½ y_cᵀα_c − Σ ln L_ii − n/2 ln 2π) and the α_c.
    fn value_and_weights(&mut self, ys: &[&[f64]]) -> (f64, Vec<Vec<f64>>) {
        let n = ys[0].len();
        let logdet: f64 = (0..n).map(|i| self.l[(i, i)].ln()).sum();
        let constant = -logdet - 0.5 * n as f64 * (2.0 * std::f64::consts::PI).ln();
        let mut value = 0.0;
        let mut alphas = Vec::with_capacity(ys.len());
        for y in ys {
            let a = self.solve(y);
            value += -0.5 * y.iter().zip(&a).map(|(p, q)| p * q).sum::<f64>() + constant;
            alphas.push(a);
        }
        (value, alphas)
    }

    /// K⁻¹ (lower triangle) from L.
    fn invert(&mut self) {
        let buf = self.buf.as_mut().expect("sized by resize");
        llt::inverse::inverse(self.kinv.as_mut(), self.l.as_ref(), Par::Seq, MemStack::new(buf));
    }

    /// Adds ½ tr(W ∂K/∂θ) over the off-diagonal pairs to `grad` for the
    /// length scales, s², α and the warp exponents; returns tr W (compiled
    /// for the widest SIMD the CPU offers, chosen at run time).
    fn accumulate_gradient(
        &self,
        kernel: &Kernel,
        x: &Columns,
        slots: &[Option<usize>],
        alphas: &[Vec<f64>],
        grad: &mut [f64],
    ) -> f64 {
        pulp::Arch::new().dispatch(Gradient { ws: self, kernel, x, slots, alphas, grad })
    }

    #[inline(always)]
    fn gradient_body(
        &self,
        kernel: &Kernel,
        x: &Columns,
        slots: &[Option<usize>],
        alphas: &[Vec<f64>],
        grad: &mut [f64],
    ) -> f64 {
        let (n, d, s2) = (x.n, kernel.lengths.len(), kernel.variance);
        let mo = alphas.len() as f64;
        let inv_l2: Vec<f64> = kernel.lengths.iter().map(|l| 1.0 / (l * l)).collect();
        let (mut w, mut wh) = (vec![0.0; n], vec![0.0; n]);
        let mut trace_w = 0.0;
        for j in 0..n {
            trace_w += alphas.iter().map(|a| a[j] * a[j]).sum::<f64>() - mo * self.kinv[(j, j)];
            let m = n - j - 1;
            let (w, wh) = (&mut w[j + 1..], &mut wh[j + 1..]);
            let kinv_j = &lower_from(&self.kinv, j)[1..];
            let k_j = &lower_from(&self.k, j)[1..];
            for (wv, ki) in w.iter_mut().zip(kinv_j) {
                *wv = -mo * ki;
            }
            for a in alphas {
                let aj = a[j];
                for (wv, ai) in w.iter_mut().zip(&a[j + 1..]) {
                    *wv += ai * aj;
                }
            }
            // s² h; the squared exponential's h is g = K / s² off the diagonal.
            if self.h.nrows() == n {
                let h_j = &lower_from(&self.h, j)[1..];
                wh.iter_mut().zip(w.iter()).zip(h_j).for_each(|((o, a), h)| *o = a * s2 * h);
            } else {
                wh.iter_mut().zip(w.iter()).zip(k_j).for_each(|((o, a), k)| *o = a * k);
            }
            let (w, wh): (&[f64], &[f64]) = (&w[..m], &wh[..m]);
            grad[d] += lanes(m, |i| w[i] * k_j[..m][i]);
            if self.da.nrows() == n {
                let da_j = &lower_from(&self.da, j)[1..][..m];
                grad[d + 1] += s2 * lanes(m, |i| w[i] * da_j[i]);
            }
            for (k, il2) in inv_l2.iter().enumerate() {
                let (xk, xj) = (&x.col(k)[j + 1..][..m], x.col(k)[j]);
                grad[k] += il2 * lanes(m, |i| wh[i] * (xk[i] - xj) * (xk[i] - xj));
                if let Some(s) = slots[k] {
                    let (dk, dj) = (&x.dcol(k)[j + 1..][..m], x.dcol(k)[j]);
                    grad[s] -= il2 * lanes(m, |i| wh[i] * (xk[i] - xj) * (dk[i] - dj));
                }
            }
        }
        trace_w
    }
}

/// One column below the diagonal: K = s² g(u), and h and ∂g/∂ln α where
/// kept, with the kernel's shape function `f` (one loop per kernel family,
/// so that it vectorises).
#[inline(always)]
fn shape_column(
    u: &[f64],
    s2: f64,
    k: &mut [f64],
    h: Option<&mut [f64]>,
    da: Option<&mut [f64]>,
    f: impl Fn(f64) -> (f64, f64, f64),
) {
    match (h, da) {
        (None, _) => {
            for (k, v) in k.iter_mut().zip(u) {
                *k = s2 * f(*v).0;
            }
        }
        (Some(h), None) => {
            for ((k, h), v) in k.iter_mut().zip(h.iter_mut()).zip(u) {
                let (g, hv, _) = f(*v);
                (*k, *h) = (s2 * g, hv);
            }
        }
        (Some(h), Some(da)) => {
            for (((k, h), da), v) in k.iter_mut().zip(h.iter_mut()).zip(da.iter_mut()).zip(u) {
                (*k, *h, *da) = {
                    let (g, hv, dv) = f(*v);
                    (s2 * g, hv, dv)
                };
            }
        }
    }
}

/// [`LmlWorkspace::fill_pairs`] as a SIMD-dispatched operation (a closure
/// would not be inlined into the feature-enabled function).
struct FillPairs<'a> {
    ws: &'a mut LmlWorkspace,
    kernel: &'a Kernel,
    x: &'a Columns,
    noise_var: f64,
}

impl pulp::WithSimd for FillPairs<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        self.ws.fill_pairs_body(self.kernel, self.x, self.noise_var)
    }
}

/// [`LmlWorkspace::accumulate_gradient`] as a SIMD-dispatched operation.
struct Gradient<'a> {
    ws: &'a LmlWorkspace,
    kernel: &'a Kernel,
    x: &'a Columns,
    slots: &'a [Option<usize>],
    alphas: &'a [Vec<f64>],
    grad: &'a mut [f64],
}

impl pulp::WithSimd for Gradient<'_> {
    type Output = f64;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> f64 {
        self.ws.gradient_body(self.kernel, self.x, self.slots, self.alphas, self.grad)
    }
}

/// Σ_{i < n} f(i) in four interleaved partial sums: independent add
/// chains that the compiler can vectorise (a single running sum cannot be
/// reordered).
#[inline(always)]
fn lanes(n: usize, f: impl Fn(usize) -> f64) -> f64 {
    let mut acc = [0.0; 4];
    let main = n - n % 4;
    for i in (0..main).step_by(4) {
        for (l, a) in acc.iter_mut().enumerate() {
            *a += f(i + l);
        }
    }
    let tail: f64 = (main..n).map(&f).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Column `j` of `m` from the diagonal down.
#[inline(always)]
fn lower_from(m: &Mat<f64>, j: usize) -> &[f64] {
    let col = m.col(j).try_as_col_major().expect("faer columns are contiguous");
    &col.as_slice()[j..]
}

/// Column `j` of `m` from the diagonal down, mutable.
#[inline(always)]
fn lower_from_mut(m: &mut Mat<f64>, j: usize) -> &mut [f64] {
    let col = m.col_mut(j).try_as_col_major_mut().expect("faer columns are contiguous");
    &mut col.as_slice_mut()[j..]
}

/// θ index of each input's warp exponent (None: not warped).
fn warp_slots(ratios: &[Option<f64>], d: usize, nk: usize) -> Vec<Option<usize>> {
    let mut slot = vec![None; d];
    let mut m = nk;
    for (k, r) in ratios.iter().take(d).enumerate() {
        if r.is_some() {
            slot[k] = Some(m);
            m += 1;
        }
    }
    slot
}

/// Warped inputs and their λ-derivatives, one contiguous column per input.
struct Columns {
    /// Points.
    n: usize,
    /// `x[k * n + i]`: input k of point i.
    x: Vec<f64>,
    /// `dw[k * n + i]`: ∂w_ik/∂λ_k.
    dw: Vec<f64>,
}

impl Columns {
    fn new(xw: &[f64], dw: &[f64], d: usize, n: usize) -> Self {
        let t = |a: &[f64]| (0..d * n).map(|m| a[(m % n) * d + m / n]).collect();
        Columns { n, x: t(xw), dw: t(dw) }
    }

    #[inline(always)]
    fn col(&self, k: usize) -> &[f64] {
        &self.x[k * self.n..(k + 1) * self.n]
    }

    #[inline(always)]
    fn dcol(&self, k: usize) -> &[f64] {
        &self.dw[k * self.n..(k + 1) * self.n]
    }
}
