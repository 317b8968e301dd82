//! The paper's experiments on its synthetic data: Table 1 (`table1`), the K study with its
//! error measures and the choice of K (`sweep`), and the samplers' ESS per second across K
//! (`bench`).

pub mod bench;
pub mod sweep;
pub mod table1;
