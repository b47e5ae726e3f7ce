// Tone mapping: linear radiance → display sRGB in [0, 1]. The same operators as the CPU path
// (radiosity_image's tone map, used by `radiosity render`); a GPU test checks that both agree
// on a table of values. Keep the two in step.

const OP_LINEAR: u32 = 0u;
const OP_REINHARD: u32 = 1u;
const OP_ACES: u32 = 2u;

// Rec. 709 relative luminance of a linear triple (radiosity_core::Rgb::luminance).
fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Operator on exposed radiance, result display-linear in [0, 1] per channel
// (radiosity_image::tone_map after the exposure).
fn tone_operator(x_in: vec3<f32>, op: u32) -> vec3<f32> {
    // Negative and NaN channels count as 0 (a NaN compares false).
    let x = select(vec3<f32>(0.0), x_in, x_in > vec3<f32>(0.0));
    if op == OP_REINHARD {
        // Reinhard et al. 2002, eq. 3, on luminance; the colour is scaled by L_d / L so its
        // hue is kept, and a saturated channel that then exceeds 1 is clipped.
        let l = luminance(x);
        if !(l > 0.0) {
            return vec3<f32>(0.0);
        }
        return min(x * (1.0 / (1.0 + l)), vec3<f32>(1.0));
    }
    if op == OP_ACES {
        // Narkowicz 2015, "ACES Filmic Tone Mapping Curve" (fit of the ACES RRT + ODT).
        let a = 2.51;
        let b = 0.03;
        let c = 2.43;
        let d = 0.59;
        let e = 0.14;
        return clamp((x * (a * x + b)) / (x * (c * x + d) + e), vec3<f32>(0.0), vec3<f32>(1.0));
    }
    return min(x, vec3<f32>(1.0));
}

// sRGB opto-electronic transfer function (IEC 61966-2-1), per channel, on [0, 1].
fn srgb_encode(linear_in: vec3<f32>) -> vec3<f32> {
    let linear = clamp(linear_in, vec3<f32>(0.0), vec3<f32>(1.0));
    let lo = linear * 12.92;
    let hi = 1.055 * pow(linear, vec3<f32>(1.0 / 2.4)) - vec3<f32>(0.055);
    return select(hi, lo, linear <= vec3<f32>(0.0031308));
}

// Radiance (W/sr/unit²) → display value: exposure (×2^EV, passed as `exposure_scale`),
// operator, sRGB encoding.
fn tone_map(radiance: vec3<f32>, exposure_scale: f32, op: u32) -> vec3<f32> {
    return srgb_encode(tone_operator(radiance * exposure_scale, op));
}

// False colour ramp for t in [0, 1]: Turbo (Mikhailov 2019, polynomial fit), display values.
fn false_colour(t_in: f32) -> vec3<f32> {
    let t = clamp(t_in, 0.0, 1.0);
    let v4 = vec4<f32>(1.0, t, t * t, t * t * t);
    let v2 = v4.zw * v4.z;
    let r = dot(v4, vec4<f32>(0.13572138, 4.61539260, -42.66032258, 132.13108234)) + dot(v2, vec2<f32>(-152.94239396, 59.28637943));
    let g = dot(v4, vec4<f32>(0.09140261, 2.19418839, 4.84296658, -14.18503333)) + dot(v2, vec2<f32>(4.27729857, 2.82956604));
    let b = dot(v4, vec4<f32>(0.10667330, 12.64194608, -60.58204836, 110.36276771)) + dot(v2, vec2<f32>(-89.90310912, 27.34824973));
    return clamp(vec3<f32>(r, g, b), vec3<f32>(0.0), vec3<f32>(1.0));
}
