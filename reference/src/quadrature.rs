//! Gauss–Legendre quadrature in f64 (Golub–Welsch would do too; here Newton's iteration
//! on P_n, as in *Numerical Recipes* §4.6).

/// Nodes and weights of the `n`-point Gauss–Legendre rule on [a, b].
pub fn gauss_legendre(n: usize, a: f64, b: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    let mid = 0.5 * (a + b);
    let half = 0.5 * (b - a);
    for i in 0..n {
        // Initial guess (Tricomi), then Newton on P_n.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0f64, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((mid + half * x, half * w));
    }
    out
}

/// ∫ f over [a, b] split into `pieces` equal intervals, each with an `n`-point rule.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, pieces: usize, n: usize) -> f64 {
    let h = (b - a) / pieces as f64;
    let rule = gauss_legendre(n, 0.0, h);
    (0..pieces)
        .map(|p| {
            let x0 = a + p as f64 * h;
            rule.iter().map(|&(x, w)| w * f(x0 + x)).sum::<f64>()
        })
        .sum()
}

/// Gauss–Kronrod 7–15 nodes (positive half, Kronrod abscissae) and weights on [−1, 1]
/// (Piessens et al., *QUADPACK*, 1983, `qk15`).
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
const WG: [f64; 4] = [0.129_484_966_168_869_7, 0.279_705_391_489_276_7, 0.381_830_050_505_118_9, 0.417_959_183_673_469_4];

/// One Gauss–Kronrod 7–15 step on [a, b]: the Kronrod estimate and |Kronrod − Gauss|.
fn gk15(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut k = fc * WGK[7];
    let mut g = fc * WG[3];
    for j in 0..7 {
        let x = h * XGK[j];
        let s = f(c - x) + f(c + x);
        k += WGK[j] * s;
        if j % 2 == 1 {
            g += WG[j / 2] * s;
        }
    }
    (k * h, ((k - g) * h).abs())
}

/// ∫ f over [a, b] by adaptive Gauss–Kronrod bisection to absolute tolerance `tol`.
pub fn adaptive(f: &impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    fn rec(f: &impl Fn(f64) -> f64, a: f64, b: f64, tol: f64, whole: (f64, f64), depth: u32) -> f64 {
        let (est, err) = whole;
        if err <= tol || depth >= 24 || (b - a).abs() < 1e-14 {
            return est;
        }
        let m = 0.5 * (a + b);
        let left = gk15(f, a, m);
        let right = gk15(f, m, b);
        rec(f, a, m, 0.5 * tol, left, depth + 1) + rec(f, m, b, 0.5 * tol, right, depth + 1)
    }
    rec(f, a, b, tol, gk15(f, a, b), 0)
}
