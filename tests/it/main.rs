//! drapelab's integration tests: physics (force balance, exact solutions, symmetry, agreement of
//! solvers, stability), the command line (bad input), and real clients reading the recordings.

mod bodies;
mod calibrate;
mod cli;
mod contact;
mod cusick;
mod docs;
mod dynamics;
mod edges;
mod engine;
mod equilibria;
mod fabrics;
mod fuzz;
mod garment;
mod layering;
mod loads;
mod module_graph;
mod patterns;
mod pipeline;
mod recordings;
mod refusals;
mod restart;
mod runs;
mod self_contact;
mod sensitivity;
mod sewing;
mod slurm;
mod stress;
mod subpixel;
mod support;
mod surface;
mod wrinkles;
