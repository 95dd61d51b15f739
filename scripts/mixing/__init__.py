"""scripts/mixing — the analysis of Jiang's (2021) Chapter 4 mixing campaign (docs/mixing.md).

Modules:
    deposit   read a frame of an H5MD trajectory (the one place that knows the file layout), cut
              regions (second-pass cells, compression cubes)
    lens      the exact sphere-sphere lens volume (seed eqs 39-40)
    params    mixing parameters phi_v, phi_m, e, n, rho_b and Z at the Table 4-2 points
    elastic   strains (best fit to particle displacements, eqs 46-50; from the wall), wall
              stresses, the orthotropic 3 x 3 fit with its condition number, M and K0
    stats     the seed's statistics (mean after dropping the highest and the lowest value)
    plots     front/side views of a deposit and the mixing-parameter strip plots (Figs 4-11, 4-12)
"""
