/* shade_chi2.c - chi-square quantile (shade_chi2.h). */
#include "shade_chi2.h"
#include <math.h>

/* Regularised upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a):
 * the power series of P = 1 - Q below x = a + 1, the continued fraction
 * of Q above, evaluated by modified Lentz (both converge fast there;
 * Abramowitz & Stegun 6.5.29 and 6.5.31). */
static double gamma_q(double a, double x)
{
    if (!(x > 0.0)) return 1.0;
    double lead = exp(-x + a * log(x) - lgamma(a));
    if (x < a + 1.0) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 1000 && fabs(term) > fabs(sum) * 1e-15; n++) {
            term *= x / (a + n);
            sum += term;
        }
        return 1.0 - sum * lead;
    }
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 1000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < tiny) d = tiny;
        c = b + an / c;
        if (fabs(c) < tiny) c = tiny;
        d = 1.0 / d;
        double del = d * c;
        h *= del;
        if (fabs(del - 1.0) < 1e-15) break;
    }
    return lead * h;
}

double shade_chi2_inv_q(double df, double y)
{
    if (!(df > 0.0) || !(y > 0.0) || !(y < 1.0)) return 0.0;
    /* P(chi^2_df > x) = Q(df/2, x/2) falls from 1 at x = 0: bisect */
    double lo = 0.0, hi = df + 10.0 * sqrt(2.0 * df) + 10.0;
    while (gamma_q(0.5 * df, 0.5 * hi) > y && hi < 1e6) hi *= 2.0;
    for (int it = 0; it < 200 && hi - lo > 1e-13 * hi; it++) {
        double mid = 0.5 * (lo + hi);
        if (gamma_q(0.5 * df, 0.5 * mid) > y) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}
