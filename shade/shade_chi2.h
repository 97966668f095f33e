/* shade_chi2.h - the chi-square quantile POV-Ray's sampling rules use
 * (focal blur's and media's confidence tests). */
#ifndef PT_SHADE_CHI2_H
#define PT_SHADE_CHI2_H

/* Cephes' chdtri: the x with P(chi^2_df > x) = y (0 < y < 1, df > 0); 0
 * outside that domain. */
double shade_chi2_inv_q(double df, double y);

#endif
