"""The physical world of one robot in a block maze: walls, motion, sensors, odometry.

Coordinates are world units of the profile (``unit`` / ``px``). The origin is the top-left
corner of block (0, 0); x grows to the right and y grows *downwards*, like the grid, so block
(i, j) spans ``[i*cell, (i+1)*cell] x [j*cell, (j+1)*cell]``.

Headings are degrees in [0, 360): 0 = +x (right/east on the screen), 90 = +y (down the
page), i.e. clockwise on the screen, so a positive change of heading is a right turn.
:data:`HEADING_ANGLES` gives the angle of each of a maze's start headings.

Walls are pymunk segments on the exposed faces of wall blocks, collinear faces merged, with
the grid's outer edge closed as well, so a robot leaving through an exit on the boundary
stops just outside the grid. The robot is a dynamic circle pulled by a kinematic control
body through a pivot joint (linear velocity) and a gear joint (angular velocity), both with
``max_bias = 0``; the robot's own velocity is never written, so the solver keeps it out of
the walls. Distance sensors march the ray through the block grid (exact faces, no physics
query); touch sensors look for wall within a small tolerance on their side's 90-degree arc.

A contact with a wall is a *touch* when the robot meets the wall with a touch sensor's bumper
(the wall lies within that sensor's 90-degree arc) at no more than ``TOUCH_SPEED`` blocks a
second along the contact's normal: what a program that feels for walls with its touch sensor
does on purpose. Every other contact (on a side without a touch sensor, or faster) is a
*collision*. Contacts that start again within ``_COLLISION_GAP`` of the last one ending are the
same contact, of the kind it started as.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import pymunk
from pymunk._chipmunk import lib as _cp

from .commands import (
    Command,
    MotorPower,
    MoveAtPower,
    Stop,
    TurnByDegrees,
    WheelPowers,
)
from .maze import Maze
from .noise import NoiseSettings, motor_gains, noise_settings, turn_factor
from .profiles import Profile, get_profile
from .sensor_kinds import MOUNTS, SENSOR_KINDS, Readings, sensor_kind
from .sensors import SensorSpec, check_ports

TURN_DONE = "turn_done"
COLLISION = "collision"
TOUCH = "touch"
EXIT = "exit"
#: fastest approach (blocks per second, along the contact normal) that still counts as a touch
TOUCH_SPEED = 1.5

#: maze heading name -> world heading in degrees (0 = right, clockwise)
HEADING_ANGLES: dict[str, float] = {"right": 0.0, "down": 90.0, "left": 180.0, "up": 270.0}

_ROBOT = 1
_WALL = 2
#: a turn counts as finished when the heading is this close to its target (radians)
_TURN_EPS = 1e-7
#: contacts that start again within this time after the last one ended are the same collision
_COLLISION_GAP = 0.1
_COS45 = math.sqrt(0.5)
#: a step that moved the robot less than this share of a block, with its motors off and no
#: turn under way, leaves it standing to the eye (see World.settled)
_SETTLED_SHARE = 1e-9
_NO_EVENTS: tuple[str, ...] = ()
# the chipmunk calls of the hot loop, bypassing pymunk's per-call wrappers (pymunk is pinned <8)
_space_step = _cp.cpSpaceStep
_get_position = _cp.cpBodyGetPosition
_get_angle = _cp.cpBodyGetAngle
_get_angular_velocity = _cp.cpBodyGetAngularVelocity
_set_position = _cp.cpBodySetPosition
_set_angle = _cp.cpBodySetAngle
_set_velocity = _cp.cpBodySetVelocity
_set_angular_velocity = _cp.cpBodySetAngularVelocity
_get_impulse = _cp.cpConstraintGetImpulse


class WorldError(ValueError):
    """A world cannot be built from this maze, profile or configuration."""


class Pose(NamedTuple):
    x: float
    y: float
    heading: float


@dataclass(frozen=True)
class Odometry:
    """What the run has done so far, for metrics and the run record."""

    time: float
    distance: float
    turn_degrees: float
    collisions: int
    exit_time: float | None
    #: intended contacts: a touch sensor's bumper meeting a wall gently (not collisions)
    touches: int = 0


def wall_segments(maze: Maze) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """Exposed block faces as merged segments in grid coordinates (block corners).

    A face lies between a floor block and a wall block or the outside of the grid.
    """
    w, h = maze.width, maze.height

    def floor(x: int, y: int) -> bool:
        return 0 <= x < w and 0 <= y < h and maze.rows[y][x] != "#"

    segments: list[tuple[tuple[int, int], tuple[int, int]]] = []
    for j in range(h + 1):
        start = None
        for i in range(w + 1):
            face = i < w and floor(i, j - 1) != floor(i, j)
            if face and start is None:
                start = i
            elif not face and start is not None:
                segments.append(((start, j), (i, j)))
                start = None
    for i in range(w + 1):
        start = None
        for j in range(h + 1):
            face = j < h and floor(i - 1, j) != floor(i, j)
            if face and start is None:
                start = j
            elif not face and start is not None:
                segments.append(((i, start), (i, j)))
                start = None
    return segments


def _march(solid: bytes, wp: int, gx: float, gy: float, dx: float, dy: float, tmax: float) -> float:
    """Grid units from (gx, gy) along unit (dx, dy) to the first solid block; -1 if > tmax.

    Coordinates are in blocks of the padded grid (the real grid shifted by one block).
    """
    ix = int(gx)
    iy = int(gy)
    idx = iy * wp + ix
    if solid[idx]:
        return 0.0
    if dx > 0.0:
        sx = 1
        tdx = 1.0 / dx
        tx = (ix + 1 - gx) * tdx
    elif dx < 0.0:
        sx = -1
        tdx = -1.0 / dx
        tx = (gx - ix) * tdx
    else:
        sx = 0
        tdx = tx = math.inf
    if dy > 0.0:
        sy = wp
        tdy = 1.0 / dy
        ty = (iy + 1 - gy) * tdy
    elif dy < 0.0:
        sy = -wp
        tdy = -1.0 / dy
        ty = (gy - iy) * tdy
    else:
        sy = 0
        tdy = ty = math.inf
    while True:
        if tx < ty:
            t = tx
            idx += sx
            tx += tdx
        else:
            t = ty
            idx += sy
            ty += tdy
        if t > tmax:
            return -1.0
        if solid[idx]:
            return t


class World:
    """One robot in a maze, stepped at a fixed ``dt`` (simulated seconds)."""

    # Slots, not an instance dictionary: a world has more attributes than CPython 3.11 keeps
    # in a dictionary's shared keys, so each read in the step loop would be a dictionary
    # lookup; a slot is read at a fixed place.
    __slots__ = (
        "_body",
        "_body_ptr",
        "_box",
        "_box_key",
        "_boxes",
        "_bumpers",
        "_collisions",
        "_contacts",
        "_contacts_now",
        "_control",
        "_control_ptr",
        "_cruise",
        "_dirs",
        "_dirs_angle",
        "_distance",
        "_distance_noise",
        "_exact",
        "_exit_time",
        "_exits",
        "_free_w",
        "_gains",
        "_gear_ptr",
        "_has_exits",
        "_in_box",
        "_inv_cell",
        "_last_contact_end",
        "_moved",
        "_new_collision",
        "_no_echo",
        "_offsets",
        "_part",
        "_persistence",
        "_physics_stale",
        "_pivot_ptr",
        "_place_stale",
        "_plan",
        "_radius",
        "_reaches",
        "_readings",
        "_reaim",
        "_remembered",
        "_rng",
        "_segments",
        "_settled_moved",
        "_solid",
        "_space",
        "_space_ptr",
        "_start",
        "_step_angle",
        "_step_dt",
        "_step_dx",
        "_step_dy",
        "_step_moved",
        "_step_v",
        "_steps",
        "_tmax",
        "_touch_far",
        "_touch_reach",
        "_touches",
        "_turn_rate",
        "_turn_target",
        "_turned",
        "_v",
        "_w",
        "_walls_around",
        "_watch_exit",
        "_wheels",
        "_wp",
        "_x",
        "_y",
        "angle",
        "cell",
        "dt",
        "maze",
        "noise",
        "profile",
        "seed",
        "sensors",
        "time",
    )

    def __init__(
        self,
        maze: Maze,
        profile: Profile | str,
        sensors: Sequence[SensorSpec] | None = None,
        noise: NoiseSettings | str | None = None,
        seed: int = 0,
        dt: float = 1 / 60,
    ) -> None:
        if isinstance(profile, str):
            profile = get_profile(profile)
        if not (isinstance(dt, int | float) and 0 < dt <= 0.1):
            raise WorldError(f"dt must be a time step in seconds in (0, 0.1], not {dt!r}")
        if maze.width == 0 or maze.height == 0:
            raise WorldError(f"{maze.source}: the maze has no blocks")
        if maze.start is None:
            raise WorldError(f"{maze.source}: the maze has no start")
        if maze.is_wall(*maze.start):
            raise WorldError(f"{maze.source}: the start {maze.start} is not on a floor block")
        if isinstance(noise, str):
            noise = noise_settings(noise, profile)
        elif noise is None:
            noise = noise_settings(profile.noise, profile)
        self.maze = maze
        self.profile = profile
        self.noise = noise
        #: the distance noise (relative, absolute), or () for none
        self._distance_noise = (
            (noise.distance_relative, noise.distance_absolute)
            if noise.distance_relative or noise.distance_absolute
            else ()
        )
        self._no_echo = profile.no_echo
        self.seed = seed
        self.dt = float(dt)
        # a maze's own block size counts when it was written for this profile
        own_cell = maze.cell if maze.profile in (None, profile.name) else None
        self.cell = float(own_cell) if own_cell is not None else profile.cell
        if 2 * profile.robot_radius >= self.cell:
            raise WorldError(
                f"the {profile.name} robot ({2 * profile.robot_radius:g} {profile.unit} wide) "
                f"does not fit the maze's {self.cell:g} {profile.unit} blocks"
            )
        self._radius = profile.robot_radius
        self._turn_rate = math.radians(profile.turn_rate)
        self._touch_reach = profile.robot_radius + 0.005 * self.cell
        #: farther than this from a side, no wall on that side is within the touch reach
        self._touch_far = self._touch_reach * (1.0 + 1e-9) + 1e-9 * self.cell
        self._settled_moved = _SETTLED_SHARE * self.cell
        self._tmax = profile.sensor_range / self.cell
        self._inv_cell = 1.0 / self.cell
        #: each mount's distance from the centre, in MOUNTS order
        self._offsets = tuple(profile.sensor_offset(m) for m in MOUNTS)
        #: the mounts' unit vectors and the walls in reach, for the step being read
        self._dirs: tuple[tuple[float, float], ...] = ()
        #: the angle ``_dirs`` were made for
        self._dirs_angle = math.nan
        self._contacts_now: list[tuple[float, float]] | None = None
        # the grid padded with one ring of wall: rays and neighbour checks need no bounds test
        w, h = maze.width, maze.height
        self._wp = wp = w + 2
        solid = bytearray([1]) * (wp * (h + 2))
        exits = bytearray(wp * (h + 2))
        for y, row in enumerate(maze.rows):
            for x, ch in enumerate(row):
                if ch != "#":
                    solid[(y + 1) * wp + x + 1] = 0
        for x, y in maze.exits:
            if maze.in_bounds(x, y) and not maze.is_wall(x, y):
                exits[(y + 1) * wp + x + 1] = 1
        self._solid = bytes(solid)
        self._exits = bytes(exits)
        self._has_exits = any(exits)
        c = self.cell
        self._boxes: dict[int, tuple[float, float, float, float]] = {}
        #: block key -> the places out of reach of every wall near it (_make_reach), as needed
        self._reaches: dict[int, tuple[float, float, float, float, float, float, float, float]] = {}
        #: block key and near sides -> the wall blocks there (_walls_near), made when first needed
        self._walls_around: dict[int, tuple[tuple[float, float, float, float], ...]] = {}
        self._segments = [
            ((a * c, b * c), (p * c, q * c)) for (a, b), (p, q) in wall_segments(maze)
        ]
        sx, sy = maze.start
        self._start = ((sx + 0.5) * c, (sy + 0.5) * c, math.radians(HEADING_ANGLES[maze.heading]))
        self.set_sensors(profile.sensors if sensors is None else sensors)
        self.reset()

    # -- configuration -------------------------------------------------------------------
    def set_sensors(self, specs: Sequence[SensorSpec]) -> None:
        """Replace the sensor configuration (effective at the next read)."""
        specs = list(specs)
        for spec in specs:
            if not isinstance(spec, SensorSpec):
                raise WorldError(f"{spec!r} is not a SensorSpec")
        check_ports(specs)
        self.sensors = tuple(specs)
        # read kind by kind in the table's order (and each kind's sensors in the order given):
        # the noise of a run is drawn in that order
        plan = []
        for kind in SENSOR_KINDS:
            mine = tuple((s.port, MOUNTS.index(s.mount)) for s in specs if s.kind == kind.name)
            if mine:
                plan.append(kind.read(self, mine))
        #: the reader of each kind's sensors, for each kind carried, in the table's order
        self._plan = tuple(plan)
        self._bumpers = tuple(
            sorted({MOUNTS.index(s.mount) for s in specs if sensor_kind(s.kind).bumper})
        )
        self._readings: dict[int, float | int] | None = None

    # -- the run -------------------------------------------------------------------------
    def reset(self, seed: int | None = None) -> None:
        """Back to the start: start pose, motors off, time and odometry zero, noise re-seeded.

        A reset world replays exactly like a new one with the same seed.
        """
        if seed is not None:
            self.seed = seed
        self._rng = random.Random(self.seed)
        self._gains = motor_gains(self.noise, self._rng)
        self._build_space()
        #: whole steps done, a float holding a whole number (exactly, below 2**53), so that
        #: the time, steps * dt, is a float product (the same number int * float gives)
        self._steps = 0.0
        #: the part of the current step already done by :meth:`step_to`, seconds
        self._part = 0.0
        self.time = 0.0
        #: the heading in radians, not wrapped: its change over time is the robot's signed
        #: turning (a plain attribute, as ``time`` is: the session reads it every control tick)
        self._x, self._y, self.angle = self._start
        self._distance = 0.0
        self._turned = 0.0
        self._collisions = 0
        self._touches = 0
        self._contacts = 0
        self._last_contact_end = -math.inf
        self._new_collision: str | None = None  # the event of a contact that just started
        self._exit_time: float | None = None
        #: whether a step may reach an exit: the maze has exits and none is reached yet
        self._watch_exit = self._has_exits
        self._wheels = (0.0, 0.0)
        self._v = 0.0
        self._w = 0.0
        self._moved = 0.0
        self._reaim = False
        self._turn_target: float | None = None
        self._readings = None
        self._free_w = 0.0
        self._physics_stale = False
        #: whether pymunk's body lags behind only in its place (after steps _advance found
        #: pymunk would take exactly as free motion): its velocities are what they would be
        self._place_stale = False
        self._step_angle = self._step_v = math.nan  # the cached step of straight driving
        self._step_dt = self.dt
        self._step_dx = self._step_dy = self._step_moved = 0.0
        self._box = (math.inf, -math.inf, math.inf, -math.inf)
        #: the block ``_box`` is of (0: a corner of the padding, a wall, with no free box)
        self._box_key = 0
        #: whether the next whole step, if it ends in the free box, is the straight step
        #: ``_step_dx``, ``_step_dy`` of a robot driving straight ahead, out of contact, its
        #: centre in the box, with nothing but the pose and time to change: set by _advance for
        #: a step it found so, and cleared by anything else (a command, physics, a part step)
        self._cruise = False
        #: whether the robot's centre is in ``_box`` (as _advance's test of the box finds it);
        #: asked only out of contact, so left False while in contact
        self._in_box = False
        #: whether pymunk's next step, if it meets no wall, moves the robot exactly as free
        #: motion does (see _sync_body, which finds it so; a command or a contact clears it)
        self._exact = False
        #: pymunk steps still to go before a contact that ended is forgotten (its arbiter,
        #: whose impulses a new contact of the same pair would start from, is dropped)
        self._remembered = 0

    def _build_space(self) -> None:
        space = pymunk.Space()
        space.collision_slop = 0.001 * self.cell
        for a, b in self._segments:
            seg = pymunk.Segment(space.static_body, a, b, 0.0)
            seg.friction = 0.0
            seg.elasticity = 0.0
            seg.collision_type = _WALL
            space.add(seg)
        r = self._radius
        mass = 1.0
        moment = pymunk.moment_for_circle(mass, 0.0, r)
        body = pymunk.Body(mass, moment)
        x, y, angle = self._start
        body.position = (x, y)
        body.angle = angle
        shape = pymunk.Circle(body, r)
        shape.friction = 0.0
        shape.elasticity = 0.0
        shape.collision_type = _ROBOT
        control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        control.position = (x, y)
        control.angle = angle
        pivot = pymunk.PivotJoint(control, body, (0.0, 0.0), (0.0, 0.0))
        pivot.max_bias = 0.0
        # just enough to go from full speed backward to full speed forward in one step;
        # more lets the joint press the robot into walls between contact corrections
        top_speed = max(self.profile.max_wheel_speed, self.profile.move_speed)
        pivot.max_force = mass * 2.0 * top_speed / self.dt
        gear = pymunk.GearJoint(control, body, 0.0, 1.0)
        gear.max_bias = 0.0
        space.add(body, shape, control, pivot, gear)
        space.on_collision(_ROBOT, _WALL, begin=self._contact_begin, separate=self._contact_end)
        self._space = space
        self._space_ptr = space._space
        self._body = body
        self._body_ptr = body._body
        self._control = control
        self._control_ptr = control._body
        self._pivot_ptr = pivot._constraint
        self._gear_ptr = gear._constraint
        self._persistence = int(space.collision_persistence)

    def _contact_begin(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        if space is not self._space:
            return
        self._exact = False
        if self._contacts == 0 and self.time - self._last_contact_end > _COLLISION_GAP:
            if self._bumpers and self._is_touch(arbiter.normal):
                self._touches += 1
                self._new_collision = TOUCH
            else:
                self._collisions += 1
                self._new_collision = COLLISION
        self._contacts += 1

    def _is_touch(self, normal: pymunk.Vec2d) -> bool:
        """Whether a contact along ``normal`` (from the robot to the wall) meets a bumper
        gently: within a touch sensor's arc, at no more than TOUCH_SPEED blocks a second."""
        a = self.angle
        c = math.cos(a)
        s = math.sin(a)
        dirs = ((c, s), (-s, c), (-c, -s), (s, -c))
        nx, ny = normal.x, normal.y
        if not any(dirs[m][0] * nx + dirs[m][1] * ny >= _COS45 for m in self._bumpers):
            return False
        return self._v * (c * nx + s * ny) <= TOUCH_SPEED * self.cell

    def _contact_end(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        if space is not self._space:
            return
        self._contacts = max(0, self._contacts - 1)
        if self._contacts == 0:
            self._last_contact_end = self.time

    # -- commands ------------------------------------------------------------------------
    def apply(self, command: Command) -> None:
        """Hand the robot a motor command; it holds until the next one.

        Any command abandons a Turn by Degree in progress.
        """
        self._cruise = False
        self._exact = False
        self._turn_target = None
        p = self.profile
        if isinstance(command, WheelPowers):
            self._wheels = (command.left * p.max_wheel_speed, command.right * p.max_wheel_speed)
        elif isinstance(command, MoveAtPower):
            power = command.power
            if p.move_sign_only:
                speed = math.copysign(p.move_speed, power) if power else 0.0
            else:
                speed = p.move_speed * power
            self._wheels = (speed, speed)
        elif isinstance(command, TurnByDegrees):
            degrees = float(command.degrees)
            if not math.isfinite(degrees):
                raise WorldError(f"cannot turn by {command.degrees!r} degrees")
            self._wheels = (0.0, 0.0)
            turn = math.radians(degrees) * turn_factor(self.noise, self._rng)
            self._turn_target = self.angle + turn
        elif isinstance(command, MotorPower):
            speed = command.power * p.max_wheel_speed
            left, right = self._wheels
            self._wheels = (speed, right) if command.wheel == "left" else (left, speed)
        elif isinstance(command, Stop):
            self._wheels = (0.0, 0.0)
        else:
            raise WorldError(
                f"{command!r} is not a motor command: use WheelPowers, MotorPower, "
                "MoveAtPower, TurnByDegrees or Stop"
            )
        left, right = self._wheels
        gl, gr = self._gains
        left *= gl
        right *= gr
        self._v = v = 0.5 * (left + right)
        self._w = w = (left - right) / p.track_width
        # the control body's C setters directly (what its properties call, without their
        # Python wrappers: a program or a driver at 20 Hz sends a command nearly every tick)
        control = self._control_ptr
        a = self.angle
        _set_velocity(control, (v * math.cos(a), v * math.sin(a)))
        _set_angular_velocity(control, w)
        self._reaim = v != 0.0 and w != 0.0

    @property
    def turning(self) -> bool:
        """True while a Turn by Degree is in progress."""
        return self._turn_target is not None

    # -- stepping ------------------------------------------------------------------------
    def step(self) -> tuple[str, ...]:
        """Advance to the end of the current ``dt`` step; the events of this step
        ("turn_done", "collision", "touch", "exit").

        Where no wall is within reach of this step's motion the pose is integrated directly
        (free motion, exactly what the solver would do with nothing to collide with); anywhere
        else, and whenever the robot touches a wall, pymunk steps the world.
        """
        if self._cruise:
            # driving straight on the step _advance last worked out, from a place in the free
            # box: _advance's free motion with what it would store again left out (the angle,
            # which w = 0 leaves as it is: a0 + 0.0 is a0 for any a0 but -0.0, and the angle
            # is never -0.0, as it starts at 0 or more and only sums change it; the turn, the
            # motion and what pymunk is to be told, which the last step stored already)
            x = self._x + self._step_dx
            y = self._y + self._step_dy
            xmin, xmax, ymin, ymax = self._box
            if xmin <= x <= xmax and ymin <= y <= ymax:
                self._distance += self._step_moved
                self._x = x
                self._y = y
                steps = self._steps + 1.0
                self._steps = steps
                self.time = t = steps * self.dt
                self._readings = None
                if self._watch_exit:
                    return self._events(t, x, y, self.angle, None)
                return _NO_EVENTS
            return self._advance(self.dt, True)
        part = self._part
        if part or self._contacts or not self._in_box:
            self._part = 0.0
            return self._advance(self.dt - part, True)
        # a whole step out of contact from a place in the free box, turning in place, standing
        # or driving an arc (wheels at different speeds, or a motor imbalance): as in _advance
        # (the same floating-point operations in the same order; what would add 0.0 or store
        # what is there is left out), without its call, where the motion stays in the box
        dt = self.dt
        a0 = self.angle
        target = self._turn_target
        if target is not None:
            # turning in place: _advance's free turn
            w = (target - a0) / dt
            rate = self._turn_rate
            w = rate if w > rate else -rate if w < -rate else w
            moved = 0.0
        else:
            v = self._v
            w = self._w
            if v:
                if not w:
                    # straight ahead: _advance works the step out once, and the next steps cruise
                    return self._advance(dt, True)
                # an arc turns the robot every step, so each step is new (the cache of a
                # straight step would only be written over): its motion, as _advance works it out
                x = self._x + v * math.cos(a0) * dt
                y = self._y + v * math.sin(a0) * dt
                xmin, xmax, ymin, ymax = self._box
                if not (xmin <= x <= xmax and ymin <= y <= ymax):
                    return self._advance(dt, True)
                moved = abs(v) * dt
                self._distance += moved
                self._x = x
                self._y = y
            else:
                moved = 0.0
        self._free_w = w
        self._physics_stale = True
        a = a0 + w * dt
        if w:
            turned = abs(w) * dt
            self._turned += turned
            self._moved = moved or turned
        else:
            self._moved = moved
        steps = self._steps + 1.0
        self._steps = steps
        self.time = t = steps * dt
        self.angle = a
        self._readings = None
        # no contact can have started (no physics ran): events only when a turn may have ended
        # or an exit may have been reached
        if self._watch_exit or (target is not None and abs(target - a) < _TURN_EPS):
            return self._events(t, self._x, self._y, a, target)
        return _NO_EVENTS

    def step_to(self, t: float) -> tuple[str, ...]:
        """Advance to simulated time ``t`` inside the current step (something is due then,
        such as a program's Timer); the next :meth:`step` ends the step at its usual time.
        Its events, as :meth:`step`'s."""
        h = t - self.time
        if not 0.0 < h < self.dt - self._part:
            raise WorldError(
                f"step_to({t!r}): the time must fall inside the current step, after "
                f"{self.time:.6f} s and before {(self._steps + 1) * self.dt:.6f} s"
            )
        self._part += h
        return self._advance(h, False)

    def _advance(self, dt: float, whole: bool) -> tuple[str, ...]:
        """Move the robot on by ``dt`` seconds; ``whole``: that ends the current step."""
        target = self._turn_target
        x0 = self._x
        y0 = self._y
        a0 = self.angle
        free = False
        if self._contacts == 0:
            if target is not None:
                v = 0.0
                w = (target - a0) / dt
                rate = self._turn_rate
                w = rate if w > rate else -rate if w < -rate else w
            else:
                v = self._v
                w = self._w
            if v:
                if a0 != self._step_angle or v != self._step_v or dt != self._step_dt:
                    self._step_dt = dt
                    self._step_angle = a0
                    self._step_v = v
                    self._step_dx = v * math.cos(a0) * dt
                    self._step_dy = v * math.sin(a0) * dt
                    self._step_moved = abs(v) * dt
                x = x0 + self._step_dx
                y = y0 + self._step_dy
                moved = self._step_moved
            else:
                x = x0
                y = y0
                moved = 0.0
            box = self._box
            if not self._in_box:
                # the free box of the block the robot is in (cached per block): where its
                # centre may go without coming near a wall
                inv = self._inv_cell
                key = (int(y0 * inv) + 1) * self._wp + int(x0 * inv) + 1
                known = self._boxes.get(key)
                if known is None:
                    known = self._boxes[key] = self._make_box(key)
                self._box = box = known
                self._box_key = key
            xmin, xmax, ymin, ymax = box
            if xmin <= x <= xmax and ymin <= y <= ymax:
                # free motion: no wall within reach, so no contact can start this step
                free = True
                self._free_w = w
                self._physics_stale = True
                a = a0 + w * dt
                turned = abs(w) * dt if w else 0.0
        if free:
            self._in_box = True
            # the next whole step may be this one again (see step)
            self._cruise = whole and v != 0.0 and w == 0.0 and target is None and dt == self.dt
        else:
            self._cruise = False
            # one pymunk step, or one taken as pymunk would take it (not a method of its own:
            # a call would cost every physics step)
            if self._physics_stale:
                self._sync_body()
            exact = False
            if self._exact and not self._contacts and whole and target is None and not w:
                # the end of the step out of every wall's reach: among the places of the box's
                # block that keep the box's clearance wall by wall (_make_reach), or else of the
                # block the step ends in
                reach = self._reaches.get(self._box_key)
                if reach is None:
                    reach = self._reaches[self._box_key] = self._make_reach(self._box_key)
                ax0, ax1, ay0, ay1, bx0, bx1, by0, by1 = reach
                exact = (ax0 <= x <= ax1 and ay0 <= y <= ay1) or (
                    bx0 <= x <= bx1 and by0 <= y <= by1
                )
                if not exact:
                    exact = self._out_of_reach(x, y)
            if exact:
                # pymunk's step, which would meet no wall, moves the robot exactly as free motion
                # does (see _sync_body): that motion, with the odometry of a pymunk step; pymunk's
                # body is given the place at its next step, its motion being what the step left
                self._place_stale = True
                a = a0
                moved = math.hypot(x - x0, y - y0)
                turned = abs(a - a0)
                xmin, xmax, ymin, ymax = self._box
                self._in_box = xmin <= x <= xmax and ymin <= y <= ymax
            else:
                if self._place_stale:
                    _set_position(self._body_ptr, (x0, y0))
                    self._place_stale = False
                if target is not None:
                    # positions integrate with the previous step's velocity: plan one step ahead
                    ahead = a0 + _get_angular_velocity(self._body_ptr) * dt
                    rate = self._turn_rate
                    w = (target - ahead) / dt
                    _set_angular_velocity(self._control_ptr, max(-rate, min(rate, w)))
                elif self._reaim:
                    v = self._v
                    _set_velocity(self._control_ptr, (v * math.cos(a0), v * math.sin(a0)))
                # the C step directly: the wrapper's bookkeeping (deferred adds and removals,
                # first-step mass checks) has nothing to do for this space after it is built
                _space_step(self._space_ptr, dt)
                body = self._body_ptr
                pos = _get_position(body)
                x = pos.x
                y = pos.y
                a = _get_angle(body)
                moved = math.hypot(x - x0, y - y0)
                turned = abs(a - a0)
                if self._contacts:
                    # only asked out of contact: worked out at the step that ends the contact
                    self._in_box = False
                    self._remembered = self._persistence + 1
                else:
                    if self._remembered:
                        self._remembered -= 1
                    xmin, xmax, ymin, ymax = self._box
                    self._in_box = xmin <= x <= xmax and ymin <= y <= ymax
        if whole:
            self._steps += 1.0
            self.time = t = self._steps * self.dt
        else:
            self.time = t = self._steps * self.dt + self._part
        self._distance += moved
        self._turned += turned
        self._moved = moved or turned
        self._x = x
        self._y = y
        self.angle = a
        self._readings = None
        if target is None and not self._new_collision and not self._watch_exit:
            return _NO_EVENTS  # nothing can have happened: the common step ends here
        return self._events(t, x, y, a, target)

    def _events(
        self, t: float, x: float, y: float, a: float, target: float | None
    ) -> tuple[str, ...]:
        """What the step that just ended brought: a finished turn, a collision, the exit."""
        events = _NO_EVENTS
        if target is not None and abs(target - a) < _TURN_EPS:
            self._turn_target = None
            _set_angular_velocity(self._control_ptr, 0.0)
            self._free_w = 0.0
            events = (TURN_DONE,)
        if self._new_collision:
            events = (*events, self._new_collision)
            self._new_collision = None
        if self._watch_exit:
            inv = self._inv_cell
            if self._exits[(int(y * inv) + 1) * self._wp + int(x * inv) + 1]:
                self._exit_time = t
                self._watch_exit = False
                events = (*events, EXIT)
        return events

    def _make_box(self, key: int) -> tuple[float, float, float, float]:
        """Where the robot's centre may go in block ``key`` (an index of the padded grid)
        without coming near a wall: (xmin, xmax, ymin, ymax)."""
        wp = self._wp
        solid = self._solid
        c = self.cell
        bx = key % wp - 1
        by = key // wp - 1
        keep = self._radius + 0.02 * c  # clearance kept from any wall block
        if solid[key]:
            return (math.inf, -math.inf, math.inf, -math.inf)
        # a wall among the three blocks on each side (made while a run steps into new blocks,
        # so plain lookups rather than a generator per side)
        left = solid[key - 1 - wp] or solid[key - 1] or solid[key - 1 + wp]
        right = solid[key + 1 - wp] or solid[key + 1] or solid[key + 1 + wp]
        up = solid[key - wp - 1] or solid[key - wp] or solid[key - wp + 1]
        down = solid[key + wp - 1] or solid[key + wp] or solid[key + wp + 1]
        x0 = bx * c
        y0 = by * c
        return (
            x0 + (keep if left else 0.0),
            x0 + c - (keep if right else 0.0),
            y0 + (keep if up else 0.0),
            y0 + c - (keep if down else 0.0),
        )

    def _out_of_reach(self, x: float, y: float) -> bool:
        """Whether the robot's centre at (x, y) is among the places of the block it is in
        that keep the free box's clearance from every wall block (_make_reach)."""
        inv = self._inv_cell
        key = (int(y * inv) + 1) * self._wp + int(x * inv) + 1
        reach = self._reaches.get(key)
        if reach is None:
            reach = self._reaches[key] = self._make_reach(key)
        ax0, ax1, ay0, ay1, bx0, bx1, by0, by1 = reach
        return (ax0 <= x <= ax1 and ay0 <= y <= ay1) or (bx0 <= x <= bx1 and by0 <= y <= by1)

    def _make_reach(
        self, key: int
    ) -> tuple[float, float, float, float, float, float, float, float]:
        """Two boxes (x0, x1, y0, y1 each) that together hold the places in block ``key`` out
        of the clearance of every wall block around it: one kept from the walls straight left
        and right and from any wall in the rows above and below, the other the same turned a
        quarter (a wall on a diagonal is in a row and a column, so each box keeps clear of it)."""
        wp = self._wp
        solid = self._solid
        c = self.cell
        keep = self._radius + 0.02 * c  # the free box's clearance
        if solid[key]:
            return (math.inf, -math.inf, math.inf, -math.inf) * 2
        left = solid[key - 1]
        right = solid[key + 1]
        up = solid[key - wp]
        down = solid[key + wp]
        row_up = solid[key - wp - 1] or up or solid[key - wp + 1]
        row_down = solid[key + wp - 1] or down or solid[key + wp + 1]
        column_left = solid[key - 1 - wp] or left or solid[key - 1 + wp]
        column_right = solid[key + 1 - wp] or right or solid[key + 1 + wp]
        x0 = (key % wp - 1) * c
        y0 = (key // wp - 1) * c
        return (
            x0 + (keep if left else 0.0),
            x0 + c - (keep if right else 0.0),
            y0 + (keep if row_up else 0.0),
            y0 + c - (keep if row_down else 0.0),
            x0 + (keep if column_left else 0.0),
            x0 + c - (keep if column_right else 0.0),
            y0 + (keep if up else 0.0),
            y0 + c - (keep if down else 0.0),
        )

    def _sync_body(self) -> None:
        """Hand the directly integrated pose and motion back to pymunk before it steps again."""
        a = self.angle
        v = self._v if self._turn_target is None else 0.0
        velocity = (v * math.cos(a), v * math.sin(a))
        ptr = self._body_ptr
        _set_position(ptr, (self._x, self._y))
        _set_angle(ptr, a)
        _set_velocity(ptr, velocity)
        _set_angular_velocity(ptr, self._free_w)
        control = self._control_ptr
        _set_velocity(control, velocity)
        _set_angular_velocity(control, self._free_w)
        self._physics_stale = False
        self._place_stale = False
        # Now both bodies move alike, along the heading and not turning, if the robot drives
        # straight or stands. Then, while the joints hold no impulse and no contact is
        # remembered, a pymunk step that meets no wall changes neither velocity (the joints
        # find nothing to correct) and moves the robot by its velocity times the step, the
        # same floating-point operations as free motion; and so does every such step after it
        # until a command or a contact (which clear _exact).
        self._exact = (
            not self._free_w
            and not self._w
            and self._turn_target is None
            and not self._contacts
            and not self._remembered
            and _get_impulse(self._pivot_ptr) == 0.0
            and _get_impulse(self._gear_ptr) == 0.0
        )

    def run(self, seconds: float) -> list[tuple[float, str]]:
        """Step for ``seconds`` of simulated time; the (time, event) pairs that happened."""
        out = []
        for _ in range(round(seconds / self.dt)):
            for event in self.step():
                out.append((self.time, event))
        return out

    # -- state ---------------------------------------------------------------------------
    @property
    def pose(self) -> Pose:
        """Centre (x, y) in world units and heading in degrees, 0 = right, clockwise."""
        heading = math.degrees(self.angle) % 360.0
        return Pose(self._x, self._y, 0.0 if heading == 360.0 else heading)

    @property
    def block(self) -> tuple[int, int]:
        """The maze block (x, y) the robot's centre is in."""
        inv = self._inv_cell
        return int(self._x * inv), int(self._y * inv)

    @property
    def still(self) -> bool:
        """True while the robot stands: its motors are off, no turn is under way and the last
        step moved it not at all (so the next steps will not either)."""
        return self._turn_target is None and not (self._v or self._w or self._moved)

    @property
    def settled(self) -> bool:
        """True while the robot stands to the eye: :attr:`still`, or motors off, no turn under
        way and the last step moved it less than a billionth of a block.

        The second case is a robot stopped while pressed into a wall: the contact solver eases
        it back out by a set share of what is left each step (pymunk's collision bias, a tenth
        at 60 steps a second), so it creeps for a few seconds, over a hundred steps, before a
        step leaves it exactly where it was. Each step of that creep is smaller than the one
        before by that share, so once one moves less than a billionth of a block, all that is
        left of it is some billionths at most: nothing any view can show.
        """
        return (
            self._turn_target is None
            and not (self._v or self._w)
            and (self._moved < self._settled_moved)
        )

    @property
    def in_contact(self) -> bool:
        """True while the robot touches a wall."""
        return self._contacts > 0

    @property
    def odometry(self) -> Odometry:
        return Odometry(
            time=self.time,
            distance=self._distance,
            turn_degrees=math.degrees(self._turned),
            collisions=self._collisions,
            exit_time=self._exit_time,
            touches=self._touches,
        )

    # -- sensors -------------------------------------------------------------------------
    def read_sensors(self) -> dict[int, float | int]:
        """Readings by port for the current step, each as its kind reads the world
        (:mod:`workbench.sim.sensor_kinds`): distances in world units, touch 0/1.

        Read twice in one step, the readings (and their noise) are the same: the same dict,
        which callers must not change.
        """
        if self._readings is not None:
            return self._readings
        a = self.angle
        if a != self._dirs_angle:
            c = math.cos(a)
            s = math.sin(a)
            # unit vectors of the mounts in MOUNTS order: front, right, back, left
            self._dirs = ((c, s), (-s, c), (-c, -s), (s, -c))
            self._dirs_angle = a
        self._contacts_now = None
        out: dict[int, float | int] = {}
        for read in self._plan:
            read(out)
        self._readings = out
        return out

    # the Probe the sensor kinds read, for the step being read (read_sensors sets it up)
    def echoes(self, sensors: Sequence[tuple[int, int]], out: Readings) -> None:
        """Into ``out`` by port, for distance sensors ``(port, mount)`` (a mount is an index of
        MOUNTS), in that order: how far each one's ray meets a wall, from the sensor's place on
        the robot, with the run's distance noise (drawn in that order); the profile's no-echo
        value for a ray that meets none within range."""
        # one call for all of a set-up's distance sensors: what the rays need is looked up
        # once, and each ray is the same arithmetic as one sensor's alone
        dirs = self._dirs
        offsets = self._offsets
        x = self._x
        y = self._y
        inv = self._inv_cell
        solid = self._solid
        wp = self._wp
        tmax = self._tmax
        cell = self.cell
        noise = self._distance_noise
        for port, mount in sensors:
            dx, dy = dirs[mount]
            offset = offsets[mount]
            t = _march(
                solid, wp, (x + offset * dx) * inv + 1.0, (y + offset * dy) * inv + 1.0,
                dx, dy, tmax,
            )  # fmt: skip
            if t < 0.0:
                out[port] = self._no_echo
                continue
            d = t * cell
            if noise:
                rel, absolute = noise
                gauss = self._rng.gauss(0.0, rel * d + absolute)
                d = min(self.profile.sensor_range, max(0.0, d + gauss))
            out[port] = d

    def pressed(self, mount: int) -> bool:
        """Whether a wall touches the robot within the arc of ``mount`` (an index of MOUNTS)."""
        contacts = self._contacts_now
        if contacts is None:
            contacts = self._contacts_now = self._wall_contacts()
        if contacts:
            ux, uy = self._dirs[mount]
            for vx, vy in contacts:
                if vx * ux + vy * uy >= _COS45 * math.hypot(vx, vy):
                    return True
        return False

    def _wall_contacts(self) -> list[tuple[float, float]]:
        """Vectors from the centre to the nearest point of each wall block within reach."""
        x = self._x
        y = self._y
        cell = self.cell
        inv = self._inv_cell
        bx = int(x * inv)
        by = int(y * inv)
        reach = self._touch_reach
        fx = x - bx * cell
        fy = y - by * cell
        if reach < fx < cell - reach and reach < fy < cell - reach:
            return []  # every other block is farther than the reach: none can touch
        reach2 = reach**2
        # Only walls on the sides the robot is near can be within reach: a side farther than
        # the reach and a margin (far above any rounding of these numbers) is left out, and
        # each wall that may be near is measured exactly as ever.
        far = self._touch_far
        near = (
            (fx <= far) | ((cell - fx <= far) << 1) | ((fy <= far) << 2) | ((cell - fy <= far) << 3)
        )
        key = ((by + 1) * self._wp + bx + 1) * 16 + near
        walls = self._walls_around.get(key)
        if walls is None:
            walls = self._walls_around[key] = self._walls_near(bx, by, near)
        found = []
        for x0, x1, y0, y1 in walls:
            # to the block's nearest point: the same numbers as min(max(y, y0), y1) - y
            ny = y0 - y if y < y0 else y1 - y if y > y1 else 0.0
            nx = x0 - x if x < x0 else x1 - x if x > x1 else 0.0
            if nx * nx + ny * ny <= reach2:
                found.append((nx, ny))
        return found

    def _walls_near(
        self, bx: int, by: int, near: int
    ) -> tuple[tuple[float, float, float, float], ...]:
        """The wall blocks among block (bx, by) and its eight neighbours that are on the sides
        ``near`` names (bits: left, right, up, down; the block's own row and column always),
        row by row, each as (x0, x1, y0, y1): what _wall_contacts measures."""
        cell = self.cell
        wp = self._wp
        solid = self._solid
        rows = ((by - 1, near & 4), (by, True), (by + 1, near & 8))
        columns = ((bx - 1, near & 1), (bx, True), (bx + 1, near & 2))
        walls = []
        for j, row_near in rows:
            row = (j + 1) * wp + 1
            y0 = j * cell
            y1 = y0 + cell
            for i, column_near in columns:
                if row_near and column_near and solid[row + i]:
                    x0 = i * cell
                    walls.append((x0, x0 + cell, y0, y1))
        return tuple(walls)
