"""All light groups of a scene in one path-tracing pass (JIT variants: LLVM and CUDA).

Radiance is linear in emitter power, so the light groups of a unit are usually rendered
one by one (:mod:`metricscenes.render`): 4–6 full path-tracing passes per unit, and on a
GPU one kernel compilation per pass. Here each camera path is followed once with every
lamp of the scene switched on; each emitter contribution (an emitter hit weighted by MIS,
or a next-event estimate) is added to the accumulator of the group its emitter belongs
to. The result per group is an unbiased estimate of that group's radiance alone (the
same estimator as Mitsuba's ``path`` integrator, restricted to one group's emitters), and
the groups sum to a render with all of them on.

A scene holds one environment emitter, so a pass carries at most one sky group; the
other groups are lamps (area, spot and point emitters; a moon goes with its sky).

Each group is binned into the film's 31 bands by the film itself
(``Film.prepare_sample``, as ``specfilm`` does for ``mi.render``) and averaged per pixel
(the ``box`` filter's develop) by a block sum in a fixed order, so a group's image is
band-for-band what a ``specfilm`` would develop, and the same bits on every run.

Only JIT variants trace a Python integrator at native speed (scalar variants would call
it once per sample); :func:`render_light_groups` refuses scalar ones.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from metricscenes.geometry import CAMERA_HEIGHT_M
from metricscenes.manifest import MAX_WAVEFRONT_LANES
from metricscenes.render import ILLUMINANCE_METER_SPP, RenderError, is_jit_variant, load_scene, with_illuminance_patch
from metricscenes.spectral import WAVELENGTHS_NM


def _mis_weight(pdf_a, pdf_b):
    """Power heuristic (β = 2), as Mitsuba's path integrator."""
    import drjit as dr

    a2 = pdf_a * pdf_a
    w = a2 / (a2 + pdf_b * pdf_b)
    return dr.detach(dr.select(dr.isfinite(w), w, 0))


class _Groups:
    """The scene's emitters by group, in the forms the traced kernel reads: per group an
    ``EmitterPtr`` array to sample from, and lookups from an emitter pointer's registry
    index to its group and to its selection probability within the group.

    As Mitsuba's own emitter sampling does, an emitter whose ``sampling_weight`` is 0 is
    never chosen by next-event estimation (its selection probability is 0, so a path that
    hits it counts it in full); the others of a group are chosen uniformly, so their
    weights must be equal."""

    def __init__(self, emitter_groups: Mapping[object, int], n_groups: int):
        import drjit as dr
        import mitsuba as mi

        members: list[list] = [[] for _ in range(n_groups)]
        for emitter, group in emitter_groups.items():
            if emitter.sampling_weight() > 0:
                members[group].append(emitter)
        for group, emitters in enumerate(members):
            if len({float(e.sampling_weight()) for e in emitters}) > 1:
                raise RenderError(f"light group {group}: its emitters' sampling weights differ "
                                  "(one-pass light groups sample a group's emitters uniformly)")
        index = {e: int(dr.reinterpret_array(mi.UInt32, mi.EmitterPtr(e))[0]) for e in emitter_groups}
        size = max(index.values(), default=0) + 1
        group_of = np.full(size, n_groups, dtype=np.uint32)  # n_groups: an emitter of no group
        pmf = np.zeros(size, dtype=np.float32)  # 0: an emitter next-event estimation never chooses
        for emitter, group in emitter_groups.items():
            group_of[index[emitter]] = group
        for emitters in members:
            for e in emitters:
                pmf[index[e]] = 1.0 / len(emitters)
        self.members = [mi.EmitterPtr(emitters) if emitters else None for emitters in members]
        self.counts = [len(emitters) for emitters in members]
        self.group_table, self.pmf_table = mi.UInt32(group_of), mi.Float(pmf)

    def lookup(self, emitter):
        """(group index, selection probability within the group) of emitter pointers."""
        import drjit as dr
        import mitsuba as mi

        index = dr.minimum(dr.reinterpret_array(mi.UInt32, emitter), dr.width(self.group_table) - 1)
        return dr.gather(mi.UInt32, self.group_table, index), dr.gather(mi.Float, self.pmf_table, index)


def _sample_group_emitter(scene, groups: _Groups, group: int, si, sample, active):
    """Next-event estimation restricted to one group: an emitter of the group chosen
    uniformly (as a scene holding only that group's emitters would), a direction on it,
    and a shadow ray. Returns the direction sample (pdf including the choice) and the
    emitted radiance divided by that pdf, zero where occluded."""
    import drjit as dr
    import mitsuba as mi

    count = groups.counts[group]
    choice = dr.minimum(mi.UInt32(sample.x * count), count - 1)
    sample = mi.Point2f(sample.x * count - mi.Float(choice), sample.y)
    emitter = dr.gather(mi.EmitterPtr, groups.members[group], choice, active)
    ds, weight = emitter.sample_direction(si, sample, active)
    active &= ds.pdf != 0.0
    occluded = scene.ray_test(si.spawn_ray_to(ds.p), active)
    ds.pdf *= 1.0 / count
    return ds, dr.select(active & ~occluded, weight * count, 0), active & ~occluded


def _trace(scene, sampler, ray, groups: _Groups, max_depth: int, rr_depth: int = 5):
    """Per-group radiance along ``ray``: a list of spectra, one per group (unidirectional
    path tracing with next-event estimation and MIS, the structure of Mitsuba's ``path``;
    next-event estimation once per group and vertex, so that each group is sampled as in
    a render of that group alone)."""
    import drjit as dr
    import mitsuba as mi

    bsdf_ctx = mi.BSDFContext()
    n_groups = len(groups.counts)

    def body(sampler, ray, depth, beta, eta, active, si_prev, pdf_prev, delta_prev, sums):
        si = scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=depth == 0, active=active)
        bsdf = si.bsdf(ray)

        # An emitter hit (or the environment when the ray escapes), weighted against the
        # next-event estimate of its own group.
        ds = mi.DirectionSample3f(scene, si=si, ref=si_prev)
        hit_group, hit_pmf = groups.lookup(ds.emitter)
        pdf_nee = dr.select(delta_prev, 0, ds.emitter.pdf_direction(si_prev, ds, active & ~delta_prev) * hit_pmf)
        emitted = beta * _mis_weight(pdf_prev, pdf_nee) * ds.emitter.eval(si, active)
        hit = active & (ds.emitter != None)  # noqa: E711
        sums = [s + dr.select(hit & (hit_group == g), emitted, 0) for g, s in enumerate(sums)]

        active_next = active & (depth + 1 < max_depth) & si.is_valid()
        smooth = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
        for g in range(n_groups):
            if not groups.counts[g]:
                continue
            ds_g, em_weight, visible = _sample_group_emitter(scene, groups, g, si, sampler.next_2d(), smooth)
            bsdf_value, bsdf_pdf = bsdf.eval_pdf(bsdf_ctx, si, si.to_local(ds_g.d), visible)
            mis = dr.select(ds_g.delta, 1, _mis_weight(ds_g.pdf, bsdf_pdf))
            sums[g] = sums[g] + dr.select(visible, beta * mis * bsdf_value * em_weight, 0)

        bsdf_sample, bsdf_weight = bsdf.sample(bsdf_ctx, si, sampler.next_1d(), sampler.next_2d(), active_next)
        ray = si.spawn_ray(si.to_world(bsdf_sample.wo))
        eta *= bsdf_sample.eta
        beta *= bsdf_weight
        beta_max = dr.max(mi.unpolarized_spectrum(beta))
        active_next &= beta_max != 0
        rr_prob = dr.minimum(beta_max * eta * eta, 0.95)
        rr_active = depth >= rr_depth
        beta[rr_active] *= dr.rcp(rr_prob)
        active_next &= ~rr_active | (sampler.next_1d() < rr_prob)
        return (sampler, ray, depth + 1, beta, eta, active_next, dr.detach(si, True), bsdf_sample.pdf,
                mi.has_flag(bsdf_sample.sampled_type, mi.BSDFFlags.Delta), sums)

    # The sampler is loop state: its random number generator must advance per bounce.
    state = (sampler, mi.Ray3f(ray), mi.UInt32(0), mi.Spectrum(1), mi.Float(1), mi.Bool(True),
             dr.zeros(mi.SurfaceInteraction3f), mi.Float(1), mi.Bool(True),
             [mi.Spectrum(0) for _ in range(n_groups)])
    state = dr.while_loop(state, lambda *s: s[5], body, labels=(
        "sampler", "ray", "depth", "beta", "eta", "active", "si_prev", "pdf_prev", "delta_prev", "sums"),
        label="light groups")
    return state[-1]


def _window_rays(sensor, window: tuple[int, int, int, int], spp: int, seed: int):
    """A sampler seeded with ``seed`` and the camera rays through the pixels of ``window``
    (x, y, cols, rows of the sensor's whole film), ``spp`` per pixel, consecutive per pixel,
    with their weights: what Mitsuba's ``sample_rays`` does for a film cropped to the
    window, with the window's numbers, the film's size and the seed opaque (as literals,
    each would be a kernel of its own), so that one compiled kernel serves every window of
    every film of the same field and aspect ratio (every inset of every environment,
    whatever its scale)."""
    import drjit as dr
    import mitsuba as mi

    x0, y0, cols, rows = window
    width, height = sensor.film().size()
    sampler = sensor.sampler().fork()
    sampler.set_sample_count(spp)
    sampler.set_samples_per_wavefront(spp)
    sampler.seed(dr.opaque(mi.UInt32, seed), cols * rows * spp)
    idx = dr.arange(mi.UInt32, cols * rows * spp) // dr.opaque(mi.UInt32, spp)
    row = idx // dr.opaque(mi.UInt32, cols)
    pixel = mi.Vector2u(idx - row * dr.opaque(mi.UInt32, cols), row) + mi.Vector2u(dr.opaque(mi.UInt32, x0),
                                                                               dr.opaque(mi.UInt32, y0))
    size = mi.Vector2f(dr.opaque(mi.Float, width), dr.opaque(mi.Float, height))
    position = (mi.Vector2f(pixel) + sampler.next_2d()) / size
    # No ray differentials: their pixel footprint would make the film's size part of the kernel
    # (the projection itself depends on the field and the aspect ratio, the same for every
    # inset scale). Nothing in the scenes filters textures by footprint.
    ray, weight = sensor.sample_ray(time=sensor.shutter_open(), sample1=sampler.next_1d(), sample2=position,
                                    sample3=mi.Vector2f(0.5))
    return sampler, ray, weight


def _window_scene(env, parts, light_groups, film, *, spp: int, seed: int, max_depth: int):
    """The loaded scene of ``light_groups`` on ``film``'s whole film (the same for every
    crop of it: the kernel does not change with the window), its description, and the
    crop as the window to trace."""
    from metricscenes import scene as scene_mod

    whole = replace(film, crop_x=0, crop_y=0, crop_width=None, crop_height=None)
    description = scene_mod.scene_dict(env, parts, light_groups, whole, spp=spp, seed=seed, max_depth=max_depth)
    return load_scene(description), description, (film.crop_x, film.crop_y, *film.size)


def _band_means(film, sums, wavelengths, weight, spp: int) -> list[list]:
    """Each group's radiance samples (``sums``) binned by the film into its bands (and a
    unit weight), as ``specfilm`` does, and averaged over each run of ``spp`` consecutive
    lanes (a pixel's samples): a block sum in a fixed order, no atomic adds, the same bits
    on every run and thread count. Evaluated: per group, one array per band."""
    import drjit as dr

    bands = WAVELENGTHS_NM.size
    per_group = [[dr.block_sum(c, spp) / spp
                  for c in film.prepare_sample(radiance * weight, wavelengths, bands + 1, weight=1.0, alpha=1.0)[:bands]]
                 for radiance in sums]
    dr.eval(per_group)
    return per_group


def render_light_groups(scene, emitter_groups: Mapping[object, int], n_groups: int, *, spp: int, seed: int,
                        max_depth: int, window: tuple[int, int, int, int] | None = None) -> list[np.ndarray]:
    """Render a loaded scene (a ``specfilm`` sensor with a ``box`` filter, every group's
    emitters on) once and return one (rows, cols, 31) float32 radiance cube per group, of
    ``window`` (x, y, cols, rows on the sensor's film; default the whole film).

    ``emitter_groups`` maps each emitter object of the scene (lamps' emitters, the
    environment, a directional moon) to its group index in ``range(n_groups)``.
    """
    import drjit as dr
    import mitsuba as mi

    if not is_jit_variant(mi.variant()):
        raise RenderError(f"one-pass light groups need a JIT variant (llvm_ad_spectral, cuda_ad_spectral), "
                          f"not {mi.variant()}")
    missing = [e for e in scene.emitters() if e not in emitter_groups]
    if missing:
        raise RenderError(f"{len(missing)} emitter(s) of the scene belong to no light group")
    sensor = scene.sensors()[0]
    film = sensor.film()
    x0, y0, cols, rows = window or (0, 0, *film.size())
    groups = _Groups(emitter_groups, n_groups)
    bands = WAVELENGTHS_NM.size
    images = [np.empty((rows, cols, bands), np.float32) for _ in range(n_groups)]
    with dr.suspend_grad():
        film.prepare([])  # (its channels: the bands and a weight)
        for index, (first, count) in enumerate(wavefront_bands(rows, cols * spp)):
            sampler, ray, weight = _window_rays(sensor, (x0, y0 + first, cols, count), spp, band_seed(seed, index))
            sums = _trace(scene, sampler, ray, groups, max_depth)
            # One kernel traces the paths; the reductions below read its stored results (left
            # lazy, each band of each group would re-trace every path in its own kernel).
            dr.eval(sums, ray.wavelengths, weight)
            for image, group in zip(images, _band_means(film, sums, ray.wavelengths, weight, spp)):
                image[first:first + count] = np.stack([np.asarray(c, dtype=np.float32) for c in group],
                                                      axis=-1).reshape(count, cols, bands)
            del sampler, ray, weight, sums  # free this band's wavefront before the next
    return images


def wavefront_bands(rows: int, lanes_per_row: int, max_lanes: int | None = None) -> list[tuple[int, int]]:
    """(first row, rows) of the bands a window of ``rows`` rows is traced in: as many whole
    rows as fit in ``max_lanes`` lanes (default :data:`MAX_WAVEFRONT_LANES`; at least one
    row), the last band the rest."""
    per_band = max(1, (max_lanes or MAX_WAVEFRONT_LANES) // lanes_per_row)
    return [(first, min(per_band, rows - first)) for first in range(0, rows, per_band)]


def band_seed(seed: int, index: int) -> int:
    """The seed of a window's band ``index``: the unit's own for the first (a window traced in
    one band renders what it did before bands), then one drawn from (seed, index), so that no
    band repeats another's random numbers (nor those of the unit seeded seed + 1)."""
    if index == 0:
        return seed
    return int(np.random.SeedSequence(seed, spawn_key=(index,)).generate_state(1)[0])


def passes(light_groups: Sequence[str]) -> list[tuple[str, ...]]:
    """How a JIT variant renders ``light_groups`` on one film: the first sky with every
    lamp group in one pass, each other sky alone (a scene holds one environment)."""
    from metricscenes.scene import SKY_GROUPS

    skies = [g for g in light_groups if g in SKY_GROUPS]
    lamps = [g for g in light_groups if g not in SKY_GROUPS]
    first = tuple(skies[:1] + lamps)
    return ([first] if first else []) + [(sky,) for sky in skies[1:]]


def render_pass(env, parts, light_groups: Sequence[str], film, *, spp: int, seed: int,
                max_depth: int) -> dict[str, np.ndarray]:
    """Radiance (rows, cols, 31) of each of ``light_groups`` on ``film`` from one render of
    the scene with all of them on: on a JIT variant by :func:`render_light_groups` (one
    group too: the same bits on every run), on a scalar one (one group only) by Mitsuba's
    ``path``."""
    import mitsuba as mi

    from metricscenes import scene as scene_mod
    from metricscenes.render import render_radiance

    if not is_jit_variant(mi.variant()):
        if len(light_groups) != 1:
            raise RenderError(f"one-pass light groups need a JIT variant, not {mi.variant()}")
        description = scene_mod.scene_dict(env, parts, light_groups, film, spp=spp, seed=seed, max_depth=max_depth)
        return {light_groups[0]: render_radiance(description, spp)}
    scene, description, window = _window_scene(env, parts, light_groups, film, spp=spp, seed=seed,
                                               max_depth=max_depth)
    groups = scene_mod.emitter_groups(description, scene, parts, light_groups)
    images = render_light_groups(scene, groups, len(light_groups), spp=spp, seed=seed, max_depth=max_depth,
                                 window=window)
    for image in images:
        if not np.all(np.isfinite(image)):
            raise RenderError("render produced non-finite radiance")
    return dict(zip(light_groups, images))


def meter_pass(env, parts, light_groups: Sequence[str], *, seed: int, max_depth: int,
               spp: int = ILLUMINANCE_METER_SPP, height_m: float = CAMERA_HEIGHT_M,
               at_xy_m: tuple[float, float] = (0.0, 0.0)) -> dict[str, np.ndarray]:
    """Horizontal spectral irradiance (31,) W·m⁻²·nm⁻¹ at (x, y, height_m) of each of
    ``light_groups``, from one trace (JIT variants): :func:`metricscenes.render.illuminance_meter`'s
    white patch seen from 10 cm above, E = π L, its ``spp`` rays followed by the one-pass
    integrator. The point and the seed are opaque, so one kernel serves every plate of
    every environment (a radiance meter's ``mi.render`` is a kernel of its own per group
    and unit: on a GPU, seconds of compiling each)."""
    import drjit as dr
    import mitsuba as mi

    from metricscenes import scene as scene_mod
    from metricscenes.render import Film

    description = with_illuminance_patch(
        scene_mod.scene_dict(env, parts, light_groups, Film(1, 1), spp=spp, seed=seed, max_depth=max_depth),
        height_m, at_xy_m)
    scene = load_scene(description)
    groups = scene_mod.emitter_groups(description, scene, parts, light_groups)
    sensor = scene.sensors()[0]
    film = sensor.film()
    with dr.suspend_grad():
        film.prepare([])
        sampler = sensor.sampler().fork()
        sampler.set_sample_count(spp)
        sampler.set_samples_per_wavefront(spp)
        sampler.seed(dr.opaque(mi.UInt32, seed), spp)
        # The film's sensitivities choose the wavelengths, as a radiance meter's sample_ray does.
        wavelengths, weight = sensor.sample_wavelengths(dr.zeros(mi.SurfaceInteraction3f), sampler.next_1d())
        above = mi.Point3f(*(dr.opaque(mi.Float, v) for v in (*map(float, at_xy_m), height_m + 0.1)))
        ray = mi.Ray3f(above, mi.Vector3f(0.0, 0.0, -1.0), 0.0, wavelengths)
        sums = _trace(scene, sampler, ray, _Groups(groups, len(light_groups)), max_depth)
        dr.eval(sums, wavelengths, weight)
        per_group = _band_means(film, sums, wavelengths, weight, spp)
    out = {g: np.pi * np.array([float(c[0]) for c in bands_of], dtype=np.float64)
           for g, bands_of in zip(light_groups, per_group)}
    for g, irradiance in out.items():
        if not np.all(np.isfinite(irradiance)):
            raise RenderError(f"illuminance meter of {g}: non-finite irradiance")
    return out


def depth_pass(env, parts, light_group: str, film, *, seed: int) -> np.ndarray:
    """Distance (m) along each pixel's ray to the first surface, 0 where it escapes: one ray
    per pixel of ``film``'s crop at positions fixed by ``seed`` (two scenes are probed along
    the same rays), traced like :func:`render_pass`'s rays, so that on a JIT variant one
    kernel serves every inset (``render.render_depth`` compiles one per crop)."""
    import drjit as dr

    scene, _, window = _window_scene(env, parts, light_group, film, spp=1, seed=seed, max_depth=2)
    _, ray, _ = _window_rays(scene.sensors()[0], window, 1, seed)
    hit = scene.ray_intersect(ray)
    distance = dr.select(hit.is_valid(), hit.t, 0.0)
    cols, rows = film.size
    return np.asarray(distance, dtype=np.float32).reshape(rows, cols)
