"""The shaders' sources and programs: the reflectance law included once, defines after the
version line, a failing shader named with its compiler's log, uniforms set by type (a
matrix row-major, as numpy holds it)."""

import os

import numpy as np
import pytest

from fragment_queries import FragmentQueries
from traj2events.renderer.context import gl_context
from traj2events.renderer.glsl import expand_includes, package_program, shader_source, with_defines


def test_shaders_take_the_reflectance_law_from_one_file():
    vertex = shader_source("terrain.vert")
    assert "#include" not in vertex and vertex.count("float reflectance_factor(") == 1
    assert vertex.startswith("#version 330 core\n")  # GLSL wants it first: the law comes after
    assert expand_includes('x\n#include "reflectance.glsl"\ny\n') == "x\n" + shader_source("reflectance.glsl") + "y\n"


def test_defines_follow_the_version_line():
    assert with_defines("#version 330 core\nx;\n", ("A", "B 2")) == "#version 330 core\n#define A\n#define B 2\nx;\n"
    assert with_defines("#version 330 core\nx;\n", ()) == "#version 330 core\nx;\n"


def test_a_shader_that_does_not_compile_is_named_with_its_log():
    context = gl_context(os.environ.get("TRAJ2EVENTS_TEST_BACKEND", "osmesa"), 4, 4)
    from OpenGL import GL as gl

    try:
        assert gl.glIsProgram(package_program(gl, "terrain_textured", ("FOOTPRINT_BOX",)))
        with pytest.raises(RuntimeError, match=r"^shaders/terrain\.vert: .*\S"):  # a define no name can start with
            package_program(gl, "terrain", ("1BAD",))
    finally:
        context.delete_context()


def test_uniforms_are_set_by_type_a_matrix_row_major():
    matrix = np.arange(16.0).reshape(4, 4)  # matrix[i, j] = 4 i + j
    declarations = "uniform mat4 m; uniform vec3 v; uniform int k; uniform float x;"
    # GLSL indexes a matrix by column first: m[j][i] is row i, column j
    with FragmentQueries(declarations, "vec4(m[1][0], m[0][3], v.y + float(k), x) + 0.0 * query(0)", 2) as query:
        query.uniforms(m=matrix, v=np.array([0.5, 2.25, 9.0]), k=3, x=0.125)
        values = query(np.zeros((1, 2, 4)))
    assert values.tolist() == [[1.0, 12.0, 5.25, 0.125]] * 2
