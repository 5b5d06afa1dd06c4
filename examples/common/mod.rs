//! What the measuring examples share.

/// E of docs/method.md, section 6:
/// E = sqrt(sum_k sum_i m_i |x_i - x_ref,i|^2) / sqrt(sum_k sum_i m_i |x_ref,i - x_i(0)|^2);
/// all nodes weigh the same here, so m_i cancels. Also the largest node distance error.
pub fn error(run: &[Vec<f64>], reference: &[Vec<f64>], d: usize) -> (f64, f64) {
    let (mut num, mut den, mut max_node) = (0.0, 0.0, 0.0f64);
    for (x, xr) in run.iter().zip(reference) {
        for i in 0..x.len() / d {
            let e2: f64 = (0..d).map(|c| (x[i * d + c] - xr[i * d + c]).powi(2)).sum();
            num += e2;
            max_node = max_node.max(e2.sqrt());
            den += (0..d).map(|c| (xr[i * d + c] - reference[0][i * d + c]).powi(2)).sum::<f64>();
        }
    }
    ((num / den).sqrt(), max_node)
}
