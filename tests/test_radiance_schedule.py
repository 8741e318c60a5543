"""The radiance schedule, without a GL context: which work items a frame plans after the voxels
or the lights changed, and how the bounces converge, headless and over progressive frames."""
import numpy as np

from engine.frame.schedule import (REFINE_PARTS, refine_parts, EVERY_VOXEL, TOUCHED_VOXELS, ClassRounds, ComposeFaces, ExtrapolateGather, FindAnchors, Gather, Inject,
                                   LightVoxels, MeasureTotals, Mipmap, RadianceSchedule, ReadTotals, RequestTotals, SortClasses,
                                   TakeCoarserSkyLight, Voxels,
                                   class_voxels, run_plan)
from engine.voxels.grid import Epoch


def run(plan, totals=()):
    """The items a plan yields, answering each MeasureTotals and ReadTotals with the next of
    `totals`."""
    totals = iter(totals)
    return run_plan(plan, lambda item: np.asarray(next(totals), float) if isinstance(item, (MeasureTotals, ReadTotals)) else None)


def geometric_totals(first=1.0, ratio=0.5, count=40):
    """Totals after each bounce of a series whose increments shrink by `ratio`."""
    return [np.full(3, first * sum(ratio ** k for k in range(n + 1))) for n in range(count)]


def of_type(items, kind):
    return [item for item in items if isinstance(item, kind)]


def progressive_frame(schedule, epoch, interleave=4, restart=False, totals=(), cones="six"):
    return run(schedule.bounce(restart=restart, bounces=0, interleave=interleave, progressive=True, epoch=epoch, cones=cones), totals)


def test_fixed_bounces_gather_k_times_and_compose_between():
    """K bounces: the face views composed from the base radiance, then K gathers of every
    voxel with the face views composed again between them (the K-th gather is the image's),
    and no totals read back."""
    schedule, epoch = RadianceSchedule(), Epoch()
    items = run(schedule.bounce(restart=True, bounces=3, interleave=4, progressive=False, epoch=epoch, cones="six"))
    assert items[:3] == [ComposeFaces((EVERY_VOXEL,), None), Mipmap((EVERY_VOXEL,)), SortClasses(1)]
    assert len(of_type(items, Gather)) == 3 and all(g.voxels.class_index == 0 for g in of_type(items, Gather))
    composes = of_type(items, ComposeFaces)
    assert composes[0] == ComposeFaces((EVERY_VOXEL,), None) and len(composes) == 3
    assert not of_type(items, MeasureTotals) and schedule.settled and schedule.iterations == 3


def test_converging_bounces_close_a_geometric_series_by_extrapolation():
    """Bounces 0: once the increments of the totals shrink by a steady ratio r = 1/2, the
    remaining bounces are added as r / (1 - r) = 1 times the last increment, and the face views
    follow; the gathers alternate between the two volumes."""
    schedule, epoch = RadianceSchedule(), Epoch()
    items = run(schedule.bounce(restart=True, bounces=0, interleave=4, progressive=False, epoch=epoch, cones="six"), geometric_totals())
    gathers = of_type(items, Gather)
    assert [g.into for g in gathers] == [1 - k % 2 for k in range(len(gathers))]
    extrapolations = of_type(items, ExtrapolateGather)
    assert len(extrapolations) == 1 and np.allclose(extrapolations[0].gain, 1.0)
    assert items[-2:] == [ComposeFaces((EVERY_VOXEL,), schedule.latest), Mipmap((EVERY_VOXEL,))]
    assert schedule.settled and schedule.iterations == len(gathers)


def test_converging_bounces_stop_when_an_increment_is_negligible():
    """A series whose second bounce adds nothing stops after it, without extrapolating."""
    schedule = RadianceSchedule()
    items = run(schedule.bounce(restart=True, bounces=0, interleave=4, progressive=False, epoch=Epoch(), cones="six"), [np.ones(3), 2 * np.ones(3), 2 * np.ones(3)])
    assert len(of_type(items, Gather)) == 2 and not of_type(items, ExtrapolateGather) and schedule.settled


def test_progressive_frames_gather_one_class_each_until_the_cycles_converge():
    """The viewer: each frame gathers one interleave class, in turn, and composes that class's
    face views with level 1 of their mips over its cells; at the end of each cycle the totals
    are computed, and read back at the start of the next frame only (no frame waits for the
    GPU's work of its own); once the series closes no frame plans any work."""
    schedule, epoch = RadianceSchedule(), Epoch()
    run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=4, spread=False, epoch=epoch))
    totals = iter(geometric_totals())
    frames = [progressive_frame(schedule, epoch, restart=True, totals=totals)]
    while not schedule.settled:
        frames.append(progressive_frame(schedule, epoch, totals=totals))
        assert len(frames) < 100
    gathered = [of_type(items, Gather) for items in frames[:-1]]
    assert all(len(g) == 1 for g in gathered)
    assert [g[0].voxels.class_index for g in gathered] == [k % 4 for k in range(len(frames) - 1)]
    assert frames[1][-2:] == [ComposeFaces((class_voxels(1),), 0), Mipmap((class_voxels(1),))]
    assert not any(of_type(items, MeasureTotals) for items in frames)
    for k, items in enumerate(frames):
        assert bool(of_type(items, ReadTotals)) == (k > 0 and bool(of_type(frames[k - 1], RequestTotals)))
        if of_type(items, ReadTotals):
            assert items[0] == ReadTotals()
    assert of_type(frames[-1], ExtrapolateGather) and not of_type(frames[-1], Gather)
    assert progressive_frame(schedule, epoch, totals=totals) == []


def test_progressive_frames_refine_with_the_tiled_cones_once_the_six_converged():
    """The tiled set named: progressive frames converge with the lecture's six cones, then
    refine with the tiled ones over the voxels sorted as one class (a run of its list is a
    region of the grid), each frame one run in REFINE_PARTS, every voxel's face views composed
    with the last run, until a series of these cycles closes; a restart goes back to the six."""
    schedule, epoch = RadianceSchedule(), Epoch()
    run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=4, spread=False, epoch=epoch))
    totals = iter(geometric_totals())
    frames = [progressive_frame(schedule, epoch, restart=True, totals=totals, cones="tiled")]
    while not schedule.settled:
        frames.append(progressive_frame(schedule, epoch, totals=totals, cones="tiled"))
        assert len(frames) < 2000
    gathers = [g for items in frames for g in of_type(items, Gather)]
    six = [g for g in gathers if g.cones == "six"]
    tiled = [g for g in gathers if g.cones == "tiled"]
    assert gathers == six + tiled and six and len(tiled) % REFINE_PARTS == 0
    assert all(g.parts == 1 for g in six)
    assert [(g.voxels.class_index, g.part, g.parts) for g in tiled] == \
        [(0, k % REFINE_PARTS, REFINE_PARTS) for k in range(len(tiled))]
    refining = [items for items in frames if of_type(items, Gather) and of_type(items, Gather)[0].cones == "tiled"]
    assert SortClasses(1) in refining[0]
    composed = [any(c.voxels == (EVERY_VOXEL,) for c in of_type(items, ComposeFaces)) for items in refining[1:REFINE_PARTS]]
    assert composed == [False] * (REFINE_PARTS - 2) + [True]
    assert progressive_frame(schedule, epoch, totals=totals, cones="tiled") == []
    restarted = progressive_frame(schedule, epoch, restart=True, totals=totals, cones="tiled")
    assert [g.cones for g in of_type(restarted, Gather)] == ["six"] and SortClasses(4) in restarted


def test_coarser_grids_refine_in_fewer_runs_of_about_as_many_anchors():
    """The refinement's runs: 96 at 128^3 and finer (a refining frame there costs about what a
    converging one does), fewer at coarser grids in proportion to the voxels their surfaces
    cover (n^2 a level), so that a refining frame traces about as many anchors as at 128^3 and
    a coarse grid settles after as many cycles, of fewer frames."""
    assert refine_parts(128, 1) == refine_parts(256, 1) == refine_parts(64, 6) == REFINE_PARTS == 96
    assert refine_parts(64, 1) == 24 and refine_parts(32, 1) == 6 and refine_parts(32, 5) == 30
    assert refine_parts(16, 1) == 2 and refine_parts(8, 1) == 1


def test_progressive_light_changes_inject_each_class_before_its_gather():
    """A light moved in progressive frames: no frame injects more than one class, each class
    is injected right before it gathers, and every class is relit within one cycle."""
    schedule, epoch = RadianceSchedule(), Epoch()
    run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=4, spread=False, epoch=epoch))
    progressive_frame(schedule, epoch, restart=True, totals=geometric_totals())
    assert run(schedule.inject(voxels_changed=False, lights_changed=True, interleave=4, spread=True, epoch=epoch)) == []
    frames = [progressive_frame(schedule, epoch, restart=True, totals=geometric_totals())]
    frames += [progressive_frame(schedule, epoch, totals=geometric_totals()) for _ in range(3)]
    injected = [of_type(items, Inject) for items in frames]
    assert all(len(i) == 1 for i in injected)
    assert sorted(i[0].voxels.class_index for i in injected) == [0, 1, 2, 3]
    for items in frames:
        inject, gather = items.index(of_type(items, Inject)[0]), items.index(of_type(items, Gather)[0])
        assert inject < gather and items[inject].voxels == items[gather].voxels


def test_progressive_voxel_changes_inject_and_compose_the_touched_voxels_before_the_gather():
    """Voxels changed by one voxelization since the last injection: only the touched voxels
    are injected, and their face views (with the class's) are composed, with the mip levels
    over their cells, before the class gathers; after two voxelizations every voxel is injected again."""
    schedule, epoch = RadianceSchedule(), Epoch()
    run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=4, spread=False, epoch=epoch))
    progressive_frame(schedule, epoch, restart=True)
    epoch = epoch.next()
    items = run(schedule.inject(voxels_changed=True, lights_changed=False, interleave=4, spread=True, epoch=epoch))
    assert items == [Inject(TOUCHED_VOXELS)]
    frame = progressive_frame(schedule, epoch, restart=True)
    compose = of_type(frame, ComposeFaces)[0]
    assert compose.voxels == (TOUCHED_VOXELS, class_voxels(1))
    mipmap = Mipmap((TOUCHED_VOXELS, class_voxels(1)))
    assert frame.index(compose) < frame.index(mipmap) < frame.index(of_type(frame, Gather)[0])
    epoch = epoch.next().next()
    assert of_type(run(schedule.inject(voxels_changed=True, lights_changed=False, interleave=4, spread=True, epoch=epoch)), Inject) == [Inject(EVERY_VOXEL)]


def test_classes_are_sorted_again_only_for_a_new_covered_list_or_interleave():
    """The class index is sorted once per state of the covered list and interleave."""
    schedule, epoch = RadianceSchedule(), Epoch()
    assert of_type(run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=4, spread=False, epoch=epoch)), SortClasses) == [SortClasses(4)]
    assert not of_type(run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=4, spread=False, epoch=epoch)), SortClasses)
    assert of_type(run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=2, spread=False, epoch=epoch)), SortClasses) == [SortClasses(2)]
    assert of_type(run(schedule.inject(voxels_changed=True, lights_changed=True, interleave=2, spread=False, epoch=epoch.next())), SortClasses) == [SortClasses(2)]


def test_voxel_light_restarted_every_frame_still_reaches_every_class():
    """The emitters' light restarted every frame (an emitter moving) goes through every class,
    one a frame, composing the face views it reads first; restarted once, it lights each class
    once and stops."""
    schedule, epoch = RadianceSchedule(), Epoch()
    chosen = []
    for _ in range(8):
        items = run(schedule.light_voxels("emitter_light", restart=True, interleave=4, epoch=epoch, level_count=1))
        assert items.index(of_type(items, ComposeFaces)[0]) < items.index(of_type(items, LightVoxels)[0])
        chosen += [item.voxels.class_index for item in of_type(items, LightVoxels)]
    assert chosen == [0, 1, 2, 3, 0, 1, 2, 3]
    frames = [run(schedule.light_voxels("sky_light", restart=k == 0, interleave=4, epoch=epoch, level_count=1))
              for k in range(5)]
    assert [[i.voxels.class_index for i in of_type(f, LightVoxels)] for f in frames] == [[0], [1], [2], [3], []]


def test_the_sky_of_moving_draws_is_relit_near_them_and_everywhere_once_they_rest():
    """While draws move, each frame's round lights the voxels in the box near them; the rest of
    their levels waits, and once nothing moves a round over every class lights all of them."""
    schedule, epoch = RadianceSchedule(), Epoch()
    near, levels = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)), frozenset({0, 1})
    for _ in range(6):
        items = run(schedule.light_voxels("sky_light", restart=True, interleave=4, epoch=epoch, level_count=1,
                                          levels=levels, resting=False, near=near))
        assert [(i.levels, i.box) for i in of_type(items, LightVoxels)] == [(levels, near)]
    assert not schedule.idle
    frames = [of_type(run(schedule.light_voxels("sky_light", restart=False, interleave=4, epoch=epoch, level_count=1,
                                                resting=True)), LightVoxels) for _ in range(5)]
    assert [[(i.voxels.class_index, i.levels, i.box) for i in f] for f in frames] == \
        [[(2, levels, None)], [(3, levels, None)], [(0, levels, None)], [(1, levels, None)], []]
    assert schedule.idle


def test_a_scroll_lights_the_voxels_it_took_in_at_once_and_the_others_once_the_camera_rests():
    """The voxels a scroll took in (the touched ones) take light in the frame of the scroll: the
    emitters' traced at every level; the sky's traced at the coarsest level and, below it, taken
    from the next coarser level (its cones wait). The scrolled level's other voxels keep their
    light while the camera moves, and are lit again over the classes once it rests."""
    scrolled = frozenset({0})
    for source in ("emitter_light", "sky_light"):
        schedule, epoch = RadianceSchedule(), Epoch()
        items = run(schedule.light_voxels(source, restart=False, interleave=4, epoch=epoch, level_count=3,
                                          scrolled=scrolled, resting=False))
        lit = [(type(i).__name__, i.voxels, i.levels) for i in items if isinstance(i, (LightVoxels, TakeCoarserSkyLight))]
        if source == "emitter_light":
            assert lit == [("LightVoxels", TOUCHED_VOXELS, None)]
        else:
            assert lit == [("TakeCoarserSkyLight", TOUCHED_VOXELS, frozenset({0, 1})), ("LightVoxels", TOUCHED_VOXELS, frozenset({2}))]
        assert not of_type(run(schedule.light_voxels(source, restart=False, interleave=4, epoch=epoch, level_count=3,
                                                     resting=False)), LightVoxels)
        rested = [of_type(run(schedule.light_voxels(source, restart=False, interleave=4, epoch=epoch, level_count=3,
                                                    resting=True)), LightVoxels) for _ in range(5)]
        assert [[(i.voxels.class_index, i.levels) for i in f] for f in rested] == \
            [[(0, scrolled)], [(1, scrolled)], [(2, scrolled)], [(3, scrolled)], []]


def test_class_rounds_restart_where_the_last_round_stopped():
    """Rounds restarted before they finished go on from the class after the last one done."""
    rounds = ClassRounds()
    rounds.restart(4)
    assert [rounds.next_class() for _ in range(2)] == [0, 1]
    rounds.restart(4)
    assert [rounds.next_class() for _ in range(5)] == [2, 3, 0, 1, None]
    rounds.restart(1)
    assert [rounds.next_class() for _ in range(2)] == [0, None]


def test_a_round_restarted_before_it_finished_covers_the_levels_of_both():
    """The light of a clipmap level that moved is due at that level's voxels; a round restarted
    for another level before it finished covers both, and one for every level covers all."""
    rounds = ClassRounds()
    rounds.restart(4, frozenset({0}))
    rounds.next_class()
    rounds.restart(4, frozenset({1}))
    assert rounds.levels == {0, 1}
    rounds.restart(4, None)
    assert rounds.levels is None
    while rounds.next_class() is not None:
        pass
    rounds.restart(4, frozenset({2}))
    assert rounds.levels == {2}


def test_a_scroll_lights_the_voxels_it_took_in_and_restarts_no_bounce():
    """A scroll changes no light, only which part of the scene a level holds: its plan finds
    the anchors, injects and gathers the touched voxels alone, and composes them with every
    voxel's face views of the scrolled level (which the scroll moved) and that level's mips
    alone, without sorting the classes; the settled bounces stay settled, and the next frame
    plans no bounce work."""
    schedule, epoch = RadianceSchedule(), Epoch()
    run(schedule.bounce(restart=True, bounces=0, interleave=4, progressive=True, epoch=epoch, cones="six"), geometric_totals(ratio=0.01))
    for _ in range(12):
        progressive_frame(schedule, epoch, totals=geometric_totals(ratio=0.01))
    assert schedule.settled
    level_zero = frozenset({0})
    scrolled = epoch.next(level_zero)
    schedule.faces_moved(level_zero)
    items = run(schedule.scrolled(scrolled))
    touched = Voxels("touched", levels=level_zero)
    assert not of_type(items, SortClasses) and of_type(items, FindAnchors)
    assert [i.voxels for i in of_type(items, Inject)] == [touched]
    assert [g.voxels for g in of_type(items, Gather)] == [touched]
    assert [c.voxels for c in of_type(items, ComposeFaces)] == [(Voxels("every", levels=level_zero),)]
    assert [m.levels for m in of_type(items, Mipmap)] == [level_zero]
    assert schedule.settled and progressive_frame(schedule, scrolled) == []
