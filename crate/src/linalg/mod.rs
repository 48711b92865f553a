//! Sparse linear algebra: a reusable symmetric (indefinite) factorization on
//! top of faer (OWNER: linalg helper).
