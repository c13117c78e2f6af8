//! Fresnel equations for unpolarised light at a dielectric interface.
