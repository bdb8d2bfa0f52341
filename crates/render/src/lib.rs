//! rpbrt's renderer: shapes, accelerators, scene building and integrators.
#![deny(missing_docs)]
