// Depth only. A phone-wire line (drawn at least one pixel of this view across, opacity = true width / drawn width)
// keeps that share of its fragments (interleaved gradient noise against the opacity): a depth map cannot hold a
// partial cover, but a filtered lookup over the dithered texels darkens by the line's true width on average.
in float v_alpha;
void main() {
  if (v_alpha < 1.0) {
    float noise = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
    if (noise >= v_alpha) discard;
  }
}
