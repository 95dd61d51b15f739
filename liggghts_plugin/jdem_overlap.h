/* jdem_overlap.h — the worst overlap beyond fix jdem/watchdog's limit that a force evaluation
 * of pair_style gran/jiang or fix wall/jiang met on this rank (kernel/jdem_watchdog.h decides
 * what is beyond). */
#ifndef JDEM_OVERLAP_H
#define JDEM_OVERLAP_H

#include <cmath>

struct JdOverlapTrip {
  double fraction;  /* overlap / the smaller radius [-]; 0: nothing beyond the limit */
  int tag_a, tag_b; /* atom ids; tag_b = 0 for a wall */
  const char *wall; /* the fix wall/jiang's id, or NULL */

  JdOverlapTrip() : fraction(0.0), tag_a(0), tag_b(0), wall(0) {}
  void note(double delta, double rmin, int a, int b, const char *w) {
    const double frac = delta / rmin;
    if (frac > fraction) {
      fraction = frac;
      tag_a = a;
      tag_b = b;
      wall = w;
    }
  }
};

#endif
