# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.7
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Tutorial: the twolink, from its URDF to tracking control
#
# This notebook follows the course report's 2-link planar arm through the toolkit: the
# model Pinocchio reads from `robots/twolink.urdf`, its dynamics checked against the
# report's closed form, the reference trajectory, two control laws, their tracking errors
# and the motion in 3-D. Run it top to bottom (*Run → Run All Cells*); it takes about
# twenty seconds.
#
# Units are SI throughout: angles [rad], rates [rad/s], torques [N·m], lengths [m].
# This notebook is kept beside `examples/tutorial.py` (the same cells as a plain Python
# script, paired by jupytext): edit either, then `jupytext --sync examples/tutorial.ipynb`.

# %%
import matplotlib.pyplot as plt
import numpy as np

from twolink_pin import (
    SimulationConfig,
    compute_metrics,
    default_trajectory,
    load_robot,
    make_scenario,
    simulate,
)

plt.rcParams["figure.dpi"] = 100

# %% [markdown]
# ## 1. The arm and its parameters
#
# The report writes the arm's dynamics with three lumped parameters
# $p = (p_1, p_2, p_3)$ [kg·m²]. `load_robot()` reads the URDF with Pinocchio and
# computes them from the links' masses and inertias ([the model and its
# derivation](../docs/model.md)).

# %%
robot = load_robot()
print(f"robot {robot.name!r}: {robot.nv} joints, end-effector frame {robot.ee_frame!r}")
print("p =", robot.p, "kg·m²")
print("link lengths", robot.link_lengths, "m; torque limits", robot.torque_limits, "N·m")

# %% [markdown]
# ## 2. M and C: Pinocchio against the closed form
#
# For this arm the report gives
#
# $$M(q) = \begin{bmatrix} p_1 + 2 p_3 \cos q_2 & p_2 + p_3 \cos q_2 \\ p_2 + p_3 \cos q_2 & p_2 \end{bmatrix},
# \qquad
# C(q, \dot q) = p_3 \sin q_2 \begin{bmatrix} -\dot q_2 & -(\dot q_1 + \dot q_2) \\ \dot q_1 & 0 \end{bmatrix}.$$
#
# The toolkit never uses these formulas in a simulation: every term comes from
# Pinocchio (`pin.crba` for $M$, `pin.computeCoriolisMatrix` for $C$). Here we compare
# the two at 200 random states.

# %%
from twolink_pin.dynamics import coriolis_matrix, mass_matrix
from twolink_pin.twolink import closed_form

rng = np.random.default_rng(0)
data = robot.create_data()
worst_m = worst_c = 0.0
for _ in range(200):
    q, v = rng.uniform(-np.pi, np.pi, 2), rng.uniform(-5.0, 5.0, 2)
    m_pin, m_report = mass_matrix(robot.model, data, q), closed_form.mass_matrix(q, robot.p)
    c_pin, c_report = coriolis_matrix(robot.model, data, q, v), closed_form.coriolis_matrix(q, v, robot.p)
    worst_m = max(worst_m, np.abs(m_pin - m_report).max())
    worst_c = max(worst_c, np.abs(c_pin - c_report).max())
print(f"largest |M_pinocchio - M_report| = {worst_m:.1e} kg·m²")
print(f"largest |C_pinocchio - C_report| = {worst_c:.1e} kg·m²/s")
assert worst_m < 1e-12 and worst_c < 1e-12

# %% [markdown]
# The formulas above are typed from the report. `derive_equations` derives them instead,
# with SymPy, from the URDF's tree and inertias: $M$, $C$ (from the Christoffel symbols),
# $g$ and the regressor $Y$, in the arm's base parameters $\beta$ — combinations of the
# links' masses, first moments and inertias and the length `l2x` (the report's $L_1$).
# Written in the $p$ they find, they are the report's formulas, symbolically
# ([equations in closed form](../docs/equations.md); `twolink-pin equations --python F.py`
# writes them as a numpy module).

# %%
from twolink_pin.symbolic import derive_equations
from twolink_pin.symbolic.formats import text_form
from twolink_pin.twolink.course_equations import course_check

equations = derive_equations(robot)
M = equations.shown(equations.M)  # beta3 = mcy2 is 0 in this URDF: its terms are left out
for name, definition in zip(equations.beta, equations.beta_definitions):
    print(text_form(equations, name), "=", text_form(equations, definition))
for r, c in ((0, 0), (0, 1), (1, 1)):
    print(f"M{r + 1}{c + 1} =", text_form(equations, M[r, c]))
check = course_check(equations)
print("p in the base parameters:", check["found"])
print("the report's M, C and regressor:", check["M"] and check["C"] and check["Y"])

# %% [markdown]
# ## 3. The reference trajectory
#
# The end effector visits the report's five via points, returning to the first; inverse
# kinematics (elbow branch $q_2 \ge 0$) turns them into joint angles, and one polynomial per
# joint passes through them with zero velocity, acceleration and jerk at both ends, so
# the motion repeats smoothly. Before any controller runs we check that the torque the
# motion needs stays within the motors' limits.

# %%
from twolink_pin.feasibility import check_torques
from twolink_pin.kinematics import joint_positions

trajectory = default_trajectory(robot)
print("via-point times", trajectory.times, "s; period", trajectory.period, "s")
print("via points q [rad]:\n", np.round(trajectory.via_q, 4))
print(check_torques(robot, trajectory).verdict())

t = np.linspace(0.0, trajectory.period, 801)
reference = trajectory.sample(t)
path = joint_positions(robot, reference.q)[:, -1, :2]  # end effector (x, y) [m]
via_xy = joint_positions(robot, trajectory.via_q)[:, -1, :2]

fig, (ax_q, ax_xy) = plt.subplots(1, 2, figsize=(10, 3.6))
for j in range(robot.nv):
    ax_q.plot(t, reference.q[:, j], label=f"$q_{{d,{j + 1}}}$")
ax_q.plot(trajectory.times, trajectory.via_q, "o", color="tab:red", ms=4)
ax_q.set(xlabel="t [s]", ylabel="desired angle [rad]", title="joint reference")
ax_q.legend()
ax_xy.plot(path[:, 0], path[:, 1], color="tab:green", label="end-effector path")
ax_xy.plot(via_xy[:, 0], via_xy[:, 1], "o", color="tab:red", label="via points")
ax_xy.set(xlabel="x [m]", ylabel="y [m]", title="end effector", aspect="equal")
ax_xy.legend(loc="lower left", fontsize=8)
fig.tight_layout()
plt.show()

# %% [markdown]
# ### The reference within the limits
#
# The report designed this polynomial "with the motor torques in mind"; the toolkit designs
# within every limit the arm has. `time_optimal` keeps the path and times it as fast as the
# velocity and effort limits allow (TOPP-RA); `optimize` finds the trajectory through the same
# via points, at the same times, with the least $\int \tau^\top \tau\,dt$, with the via points
# as hard constraints ([trajectories within limits](../docs/within_limits.md)).

# %%
from twolink_pin import optimize, time_optimal

retimed = time_optimal(robot, trajectory)
print(f"time-optimal: {retimed.duration:.3f} s instead of {trajectory.period:g} s; active limits:")
for stretch in retimed.active:
    print("  ", stretch.describe())
least = optimize(robot, trajectory, "effort")
print(
    f"least effort: ∫τᵀτ dt = {least.effort:.2f} N²·m²·s (the polynomial: {least.reference_effort:.2f}), "
    f"via points met to {least.via_error:.1e} rad"
)

# %% [markdown]
# ## 4. Two controllers
#
# Both laws use the tracking error $e = q - q_d$. The PD law with model feedforward
# (report eq. 8) is
#
# $$\tau = M(q)\,\ddot q_d + C(q, \dot q)\,\dot q_d + g(q) - K_p e - K_d \dot e,$$
#
# and the Slotine–Li adaptive law starts from parameter estimates $\hat p(0) = 0.5\,p$
# and learns them online, with $s = \dot e + \lambda e$ and $\dot q_r = \dot q_d - \lambda e$:
#
# $$\tau = Y(q, \dot q, \dot q_r, \ddot q_r)\,\hat p - K s, \qquad \dot{\hat p} = -\Gamma Y^\top s.$$
#
# `make_scenario` pairs each law (with the report's gains) with the simulated arm; each
# run below lasts 8 s (two periods), starting at $q(0) = q_d(0) + (0.1, -0.1)$ rad.

# %%
config = SimulationConfig(duration=8.0)
results = {}
for law in ("pd", "adaptive"):
    controller, plant = make_scenario(law, robot)
    results[law] = simulate(controller, plant, trajectory, config)
    rms = compute_metrics(results[law]).rms
    print(f"{law:>9}: RMS e = {np.round(rms.e, 5)} rad, RMS tau = {np.round(rms.tau, 2)} N·m")

# %% [markdown]
# ## 5. Tracking errors
#
# Both errors start at $\pm 0.1$ rad and decay to a small periodic residual. The
# adaptive law tracks although its estimates stay far from the truth after 8 s: $s \to 0$
# does not need $\hat p = p$, and $\hat p$ converges only if the motion is persistently
# exciting ([controllers](../docs/controllers.md) has the Lyapunov argument).

# %%
fig, axes = plt.subplots(1, robot.nv, figsize=(10, 3.4), sharey=True)
for law, result in results.items():
    error = result.q - result.q_des
    for j, ax in enumerate(axes):
        ax.plot(result.t, error[:, j], label=law)
for j, ax in enumerate(axes):
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set(xlabel="t [s]", title=f"joint {j + 1}")
axes[0].set_ylabel("e = q − q_d [rad]")
axes[0].legend()
fig.tight_layout()
plt.show()

adaptive = results["adaptive"]
print("p̂ at 0 s:", np.round(adaptive.p_hat[0], 3), " at 8 s:", np.round(adaptive.p_hat[-1], 3))
print("true p   :", adaptive.p_true)

# %% [markdown]
# ## 6. The motion in 3-D
#
# `inline_animation` puts the meshcat scene of a run into the notebook: the arm, the
# translucent desired "ghost", the end-effector trail, the desired path and the via
# points. The page is embedded in the output, so the animation plays in the saved
# notebook without a server. Open *Controls → Animations* in the viewer to play, pause
# and scrub; drag to turn the view.

# %%
from twolink_pin.visualization import inline_animation

inline_animation(robot, adaptive.t, adaptive.q, adaptive.q_des, via_points=via_xy)

# %% [markdown]
# ## Where next
#
# - Write your own law: one class in one file ([writing a controller](../docs/writing_a_controller.md)).
# - Tune a law live in the browser: move a gain and watch the arm, its errors and torques change,
#   `twolink-pin tune pd` ([tuning a law live](../docs/tune.md)).
# - Compare every built-in law over 30 s, as the report's Table 2: `twolink-pin compare`
#   ([comparison with the report](../docs/report_comparison.md)).
# - Any other arm from URDF, e.g. `load_robot("ur5")` ([any robot](../docs/any_robot.md)).
# - Every function and class: the [API reference](../docs/api/index.md) of the site
#   (`make docs`, then open `site/index.html`).
