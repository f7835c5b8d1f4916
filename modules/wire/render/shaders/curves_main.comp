void main() {
    uint w = gl_GlobalInvocationID.x;
    if (w >= u_wires) return;
    GpuCurveHeader h = headers[w];
    if (u_list) slot_list[u_list_first + w] = h.slot;
    if (u_persist && u_motion) {
        // This upload's reference (none for given segments) and, when asked, the motion fitted against the last.
        MotionRef to;
        to.counts = uvec4(0u);
        if ((h.flags & kHeaderGivenSegments) == 0u) to = make_ref(h);
        if ((h.flags & kHeaderFitMotion) != 0u) {
            vec4 q = fit_motion(refs[h.slot], to);
            h.motion[0] = q.x, h.motion[1] = q.y, h.motion[2] = q.z;
        }
        refs[h.slot] = to;
    }
    if (u_persist) slot_headers[h.slot] = h;
    if ((h.flags & kHeaderGivenSegments) != 0u) {  // a blended curve: its segments as they came
        uint segs = (h.flags & kHeaderClosed) != 0u ? h.node_count : h.node_count - 1u;
        for (uint k = 0u; k < 4u * segs; ++k) segments[4u * h.segment_first + k] = given(h, k);
        return;
    }
    uint n = h.node_count;
    bool closed = (h.flags & kHeaderClosed) != 0u;
    uint kind = (h.flags >> kHeaderKindShift) & kHeaderKindMask;
    uint segs = closed ? n : n - 1u;
    if (kind >= 2u) {
        c2_tangents(h, closed);
        for (uint k = 0u; k < segs; ++k) {
            dvec3 p0 = dnode(h, k), p1 = dnode(h, k + 1u);
            double len = hlen(h, k);
            // keep: the node's tension scales both its tangents (automatic; 1 for c2).
            double keep0 = keep_at(h, k), keep1 = keep_at(h, (k + 1u) % n);
            dvec3 t0 = scratch[sidx(h, k)].xyz * (len * keep0), t1 = scratch[sidx(h, (k + 1u) % n)].xyz * (len * keep1);
            uint s = 4u * (h.segment_first + k);
            segments[s] = vec4(vec3(p0), radius(h, k));
            segments[s + 1u] = vec4(vec3(t0 / 3.0), radius(h, (k + 1u) % n));
            segments[s + 2u] = vec4(vec3((p1 - p0) - (t0 + t1) / 3.0), seg_stretch(h, k));
            segments[s + 3u] = vec4(vec3(t1 / 3.0), 0.0);
        }
        return;
    }
    // Node j's tangents: t0 starts its outgoing segment j, t1 ends its incoming one (j - 1); segment j - 1 is
    // written at node j from the previous node's t0, and a closed loop's last segment at the end from node 0's t1.
    float alpha = h.kb.x, keep = 1.0 - h.kb.y, b = h.kb.z, c = h.kb.w;
    vec3 prev_t0 = vec3(0.0), first_t1 = vec3(0.0);
    for (uint j = 0u; j < n; ++j) {
        bool has_in = closed || j > 0u, has_out = closed || j + 1u < n;
        uint kin = has_in ? (j == 0u ? segs - 1u : j - 1u) : 0u;
        uint kout = has_out ? (j == segs ? 0u : j) : segs - 1u;
        vec3 cin = node(h, (kin + 1u) % n) - node(h, kin);
        vec3 cout = node(h, (kout + 1u) % n) - node(h, kout);
        vec3 din = has_in ? cin : cout;
        vec3 dout = has_out ? cout : cin;
        vec3 t0, t1;
        if (kind == 0u) {
            t0 = dout;
            t1 = din;
        } else {
            if ((h.flags & kHeaderPerNode) != 0u) {
                vec4 k = extras[h.extra_first + j];
                keep = 1.0 - k.x;
                b = k.y;
                c = k.z;
            }
            float lin = length(din), lout = length(dout);
            float rho;
            if (alpha == 1.0) rho = lout / lin;
            else if (alpha == 0.5) rho = sqrt(lout / lin);
            else rho = exp(clamp(alpha * (log(lout) - log(lin)), -80.0, 80.0));
            rho = clamp(rho, 1e-30, 1e30);
            float wt = rho / (1.0 + rho), iw = 1.0 / (1.0 + rho);
            t0 = keep * (((1.0 + b) * (1.0 + c) * rho * wt) * din + ((1.0 - b) * (1.0 - c) * iw) * dout);
            t1 = keep * (((1.0 + b) * (1.0 - c) * wt) * din + ((1.0 - b) * (1.0 + c) * iw / rho) * dout);
        }
        if (j == 0u) first_t1 = t1;
        else put_segment(h, j - 1u, node(h, j - 1u), prev_t0, t1, cin);
        prev_t0 = t0;
    }
    if (closed) put_segment(h, n - 1u, node(h, n - 1u), prev_t0, first_t1, node(h, 0u) - node(h, n - 1u));
}
