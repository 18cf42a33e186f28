"""Generated mazes survive a trip through our format and the micromouse text format unchanged."""

from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.sim.generate import generate
from workbench.sim.mazefile import format_maze, parse_maze
from workbench.sim.micromouse import format_micromouse, parse_micromouse
from workbench.sim.wallmaze import to_blocks

mazes = st.builds(
    generate,
    width=st.integers(3, 12),
    height=st.integers(3, 12),
    seed=st.integers(0, 2**32),
    style=st.sampled_from(["perfect", "braid"]),
    exit=st.sampled_from(["center", "none"]),
)


@settings(max_examples=60, deadline=None)
@given(mazes)
def test_workbench_format_round_trip(maze):
    again = parse_maze(format_maze(maze))
    assert again == maze


@settings(max_examples=60, deadline=None)
@given(mazes)
def test_micromouse_format_round_trip(maze):
    text = format_micromouse(maze)
    again = to_blocks(parse_micromouse(text))
    assert again.same_layout(maze)
    assert format_micromouse(again) == text


@settings(max_examples=20, deadline=None)
@given(
    st.builds(
        generate,
        width=st.integers(2, 8),
        height=st.integers(2, 8),
        seed=st.integers(0, 2**32),
        exit=st.just("boundary"),
    )
)
def test_boundary_exits_round_trip_through_our_format(maze):
    assert parse_maze(format_maze(maze)) == maze
    assert maze.validate() == []
