// lobe.glsl -- stable evaluation of a cosine-power lobe (DESIGN section 3).
//
// log_one_minus(delta) -> ln(1 - delta),  0 <= delta < 1
//   delta < 1/2:  -2 artanh(sigma),  sigma = delta / (2 - delta)  (2 sigma formed directly, so that
//                 delta just above FLT_MIN does not pass through a subnormal sigma),
//                 artanh(sigma) = sum_{k=0..7} sigma^(2k+1) / (2k+1)   (sigma <= 1/3: truncation < 2^-27)
//   delta >= 1/2: log(1 - delta)   (1 - delta is exact there, Sterbenz)
//   Accurate to a few ulp relative even for delta ~ 1e-30, where log(1.0 - delta) would return 0.
//
// lobe_from_delta(delta, q) -> (1 - delta)^q = cos^q
//   delta = 1 - cos, the distance from the lobe peak (0 at the peak);  q >= 0 the exponent.
//   q == 0: 1 (0^0 := 1);  delta >= 1 (cos <= 0): 0, the max(cos, 0) clamp;
//   else exp(max(q ln(1 - delta), -104)).  Never NaN, never above 1.

float log_one_minus(float delta)
{
    if (delta < 0.5) {
        float two_sigma = (2.0 * delta) / (2.0 - delta);
        float t = 0.25 * (two_sigma * two_sigma);
        float series = 1.0 + t * (1.0 / 3.0 + t * (1.0 / 5.0 + t * (1.0 / 7.0 + t * (1.0 / 9.0
                     + t * (1.0 / 11.0 + t * (1.0 / 13.0 + t * (1.0 / 15.0)))))));
        return -two_sigma * series;
    }
    return log(1.0 - delta);
}

float lobe_from_delta(float delta, float q)
{
    if (q == 0.0) {
        return 1.0;
    }
    if (!(delta < 1.0)) {
        return 0.0;
    }
    return exp(max(q * log_one_minus(delta), -104.0));
}
