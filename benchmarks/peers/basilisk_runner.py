"""Basilisk's side of ``benchmarks/spacecraft.py``: one inertial hold in LEO with Basilisk's own modules.

Runs inside ``benchmarks/.venv-basilisk`` (Basilisk pins its own numpy), so it imports nothing of this project::

    python basilisk_runner.py INPUT.json OUTPUT.json

The simulation, all of it Basilisk's (``bsk`` 2.12.1):

- ``spacecraft.Spacecraft``: the rigid hub, torque-free, at rest in inertial space, its translation under the Earth's
  gravity: ``gravityEffector`` spherical harmonics of degree 2 with the normalised C̄20 = -J2/√5 set in code (no data
  file), the Earth's fixed frame held at the input's axes by a planet-state message (J2 is axisymmetric, so its
  rotation does not matter);
- ``starTracker.StarTracker`` (its Gauss-Markov error with a zero propagation matrix: white, σ per axis about the
  body = case axes) read through ``stComm`` into the filter's attitude message;
- ``inertialUKF`` (fswAlgorithms): the square-root UKF on [σ_BN, ω_BN] whose time update integrates σ̇ = ¼ B(σ) ω with
  the torque model (no wheels here), its measurement the tracker's MRP with a fixed noise matrix, here the tracker's
  body-axis σ mapped into MRP at the held attitude (the best a user can give it: a diagonal (σ/4)² is right only
  near σ = 0, and this hold's |σ| is ~0.8). Its gyro buffer is an input message that no
  Basilisk module writes and that the filter reads only to propagate its output between tracker fixes; the filter
  runs at the fix rate, so every call carries a fix and the gyro does not enter its estimate (the message is
  linked and written once with no packet). Its process noise comes from the gyro's noise: attitude
  from the angle random walk, rate from the rate random walk, in the filter's discrete form (the Cholesky factor's
  attitude rows scaled by dt²/2, its rate rows by dt, ``inertialUKFTimeUpdate``).

INPUT: duration_s, dynamics_step_s, orbit {r_m, v_m_s, mu_m3_s2, j2, radius_m}, orbit_sample_s, inertia_kg_m2,
sigma_BN0, omega_BN0_rad_s, gyro {rate_hz, arw_rad_per_sqrt_s, rrw_rad_per_s_sqrt_s}, star_tracker
{rate_hz, sigma_rad [x, y, z]}, filter {initial_attitude_sigma_rad, initial_rate_sigma_rad_s}, seed.
OUTPUT: bsk_version, t_s, sigma_true, sigma_est, P_sigma (the filter's MRP covariance, (F, 3, 3)), omega_true,
omega_est, orbit_t_s, r_m, gravity, wall_s (ExecuteSimulation), setup_s, note.
"""

import json
import sys
import time

import numpy as np
from Basilisk.architecture import messaging
from Basilisk.fswAlgorithms import inertialUKF, stComm
from Basilisk.simulation import spacecraft, starTracker
from Basilisk.simulation.gravityEffector import SphericalHarmonicsGravityModel
from Basilisk.utilities import SimulationBaseClass, macros, simIncludeGravBody

try:
    from Basilisk import __version__ as BSK_VERSION
except ImportError:  # older wheels
    BSK_VERSION = "unknown"

NOTE = ("inertialUKF: attitude fixes only (its gyro buffer propagates the output between fixes, and the filter runs "
        "at the fix rate); hub torque-free at rest; gravity point mass + J2 by spherical harmonics")


def earth(factory, orbit):
    """The Earth as the central body: μ, R and the degree-2 zonal term, its frame fixed at the input axes."""
    body = factory.createCustomGravObject("earth", orbit["mu_m3_s2"], radEquator=orbit["radius_m"])
    body.isCentralBody = True
    model = SphericalHarmonicsGravityModel()
    model.muBody, model.radEquator, model.maxDeg = orbit["mu_m3_s2"], orbit["radius_m"], 2
    model.cBar = [[1.0], [0.0, 0.0], [-orbit["j2"] / np.sqrt(5.0), 0.0, 0.0]]
    model.sBar = [[0.0], [0.0, 0.0], [0.0, 0.0, 0.0]]
    body.gravityModel = model
    state = messaging.SpicePlanetStateMsgPayload()
    state.PlanetName = "earth"
    state.J20002Pfix = np.eye(3).tolist()
    message = messaging.SpicePlanetStateMsg().write(state)
    body.planetBodyInMsg.subscribeTo(message)
    return message


def hub(inputs):
    """The spacecraft: mass properties, initial orbit and attitude."""
    craft = spacecraft.Spacecraft()
    craft.ModelTag = "spacecraft"
    craft.hub.mHub = 500.0
    craft.hub.IHubPntBc_B = inputs["inertia_kg_m2"]
    craft.hub.r_CN_NInit = [[x] for x in inputs["orbit"]["r_m"]]
    craft.hub.v_CN_NInit = [[x] for x in inputs["orbit"]["v_m_s"]]
    craft.hub.sigma_BNInit = [[x] for x in inputs["sigma_BN0"]]
    craft.hub.omega_BN_BInit = [[x] for x in inputs["omega_BN0_rad_s"]]
    return craft


def tracker(inputs, state_message):
    """The star tracker and its interface module: white PRV noise of σ per body axis."""
    sensor = starTracker.StarTracker()
    sensor.ModelTag = "starTracker"
    sensor.RNGSeed = int(inputs["seed"]) + 1
    sensor.PMatrix = np.diag(inputs["star_tracker"]["sigma_rad"]).tolist()
    sensor.setAMatrix(np.zeros((3, 3)))
    sensor.setWalkBounds(np.zeros(3))
    sensor.scStateInMsg.subscribeTo(state_message)
    interface = stComm.stComm()
    interface.ModelTag = "stComm"
    interface.dcm_BP = np.eye(3).flatten().tolist()
    interface.stSensorInMsg.subscribeTo(sensor.sensorOutMsg)
    return sensor, interface


def mrp_b_matrix(s):
    """B(σ) of σ̇ = ¼ B(σ) ω (Schaub & Junkins eq. 3.155): a small body rotation δθ moves σ by ¼ B δθ."""
    s = np.asarray(s, dtype=float)
    cross = np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])
    return (1.0 - s @ s) * np.eye(3) + 2.0 * cross + 2.0 * np.outer(s, s)


def process_noise(inputs):
    """qNoise (6 × 6, row-major) such that one fix interval adds the gyro's random walks, in the filter's form; the
    attitude's in MRP at the held attitude (B Bᵀ = (1 + σ²)² I)."""
    dt = 1.0 / inputs["star_tracker"]["rate_hz"]
    gyro = inputs["gyro"]
    scale = (1.0 + np.sum(np.square(inputs["sigma_BN0"]))) / 4.0  # |¼ B δθ| / |δθ|
    attitude = gyro["arw_rad_per_sqrt_s"] * np.sqrt(dt) * scale / (dt * dt / 2.0)
    rate = gyro["rrw_rad_per_s_sqrt_s"] * np.sqrt(dt) / dt
    return np.diag([attitude**2] * 3 + [rate**2] * 3).flatten().tolist()


def initial_state(inputs, rng):
    """(stateInit, covarInit): the truth plus a draw of the stated σ, and that σ."""
    sigma_att = inputs["filter"]["initial_attitude_sigma_rad"] / 4.0
    sigma_rate = inputs["filter"]["initial_rate_sigma_rad_s"]
    state = np.concatenate([np.asarray(inputs["sigma_BN0"]) + rng.normal(0.0, sigma_att, 3),
                            np.asarray(inputs["omega_BN0_rad_s"]) + rng.normal(0.0, sigma_rate, 3)])
    return state.tolist(), np.diag([sigma_att**2] * 3 + [sigma_rate**2] * 3).flatten().tolist()


def tracker_noise(inputs):
    """The fix's MRP covariance at the held attitude: ¼ B(σ) diag(σ_i²) ¼ Bᵀ (the body-axis noise mapped into the
    filter's MRP measurement; the hold keeps σ at its initial value)."""
    b = mrp_b_matrix(inputs["sigma_BN0"]) / 4.0
    return b @ np.diag(np.square(inputs["star_tracker"]["sigma_rad"])) @ b.T


def filter_module(inputs, attitude_message, messages):
    """inertialUKF with its parameters as Basilisk's unit test sets them, the tracker's noise and our initial σ."""
    ukf = inertialUKF.inertialUKF()
    ukf.ModelTag = "inertialUKF"
    ukf.alpha, ukf.beta, ukf.kappa, ukf.switchMag = 0.02, 2.0, 0.0, 1.2
    ukf.stateInit, ukf.covarInit = initial_state(inputs, np.random.default_rng(inputs["seed"]))
    ukf.qNoise = process_noise(inputs)
    head = inertialUKF.STMessage()
    head.noise = tracker_noise(inputs).flatten().tolist()
    ukf.STDatasStruct.STMessages = [head]
    ukf.STDatasStruct.numST = 1
    smoothing = inertialUKF.LowPassFilterData()
    smoothing.hStep = 1.0 / inputs["star_tracker"]["rate_hz"]
    smoothing.omegCutoff = 15.0 / (2.0 * np.pi)
    ukf.gyroFilt = [smoothing, smoothing, smoothing]
    config = messaging.VehicleConfigMsgPayload()
    config.ISCPntB_B = np.asarray(inputs["inertia_kg_m2"]).flatten().tolist()
    messages["config"] = messaging.VehicleConfigMsg().write(config)
    messages["wheel_config"] = messaging.RWArrayConfigMsg().write(messaging.RWArrayConfigMsgPayload())
    messages["wheel_speeds"] = messaging.RWSpeedMsg().write(messaging.RWSpeedMsgPayload())
    messages["gyro"] = messaging.AccDataMsg().write(messaging.AccDataMsgPayload())  # no packet: never used
    ukf.STDatasStruct.STMessages[0].stInMsg.subscribeTo(attitude_message)
    ukf.massPropsInMsg.subscribeTo(messages["config"])
    ukf.rwParamsInMsg.subscribeTo(messages["wheel_config"])
    ukf.rwSpeedsInMsg.subscribeTo(messages["wheel_speeds"])
    ukf.gyrBuffInMsg.subscribeTo(messages["gyro"])
    return ukf


def build(inputs):
    """(simulation, recorders, kept): every module in its task, the recorders of truth, estimate and orbit."""
    sim = SimulationBaseClass.SimBaseClass()
    process = sim.CreateNewProcess("process")
    fix_ns = macros.sec2nano(1.0 / inputs["star_tracker"]["rate_hz"])
    process.addTask(sim.CreateNewTask("dynamics", macros.sec2nano(inputs["dynamics_step_s"])), 30)
    process.addTask(sim.CreateNewTask("sensors", fix_ns), 20)
    process.addTask(sim.CreateNewTask("fsw", fix_ns), 10)
    factory = simIncludeGravBody.gravBodyFactory()
    kept = {"planet": earth(factory, inputs["orbit"])}
    craft = hub(inputs)
    craft.gravField.gravBodies = spacecraft.GravBodyVector(list(factory.gravBodies.values()))
    sim.AddModelToTask("dynamics", craft)
    sensor, interface = tracker(inputs, craft.scStateOutMsg)
    sim.AddModelToTask("sensors", sensor)
    sim.AddModelToTask("sensors", interface)
    ukf = filter_module(inputs, interface.stAttOutMsg, kept)
    sim.AddModelToTask("fsw", ukf)
    recorders = {"truth": craft.scStateOutMsg.recorder(fix_ns), "estimate": ukf.navStateOutMsg.recorder(fix_ns),
                 "filter": ukf.filtDataOutMsg.recorder(fix_ns),
                 "orbit": craft.scStateOutMsg.recorder(macros.sec2nano(inputs["orbit_sample_s"]))}
    for recorder in recorders.values():
        sim.AddModelToTask("fsw", recorder)
    kept.update({"craft": craft, "sensor": sensor, "interface": interface, "ukf": ukf, "factory": factory})
    return sim, recorders, kept


def outputs(recorders):
    """The output arrays from the recorders, the filter's frames from its first fix on."""
    truth, estimate, filt, orbit = (recorders[k] for k in ("truth", "estimate", "filter", "orbit"))
    t = np.asarray(estimate.times()) * macros.NANO2SEC
    started = np.asarray(filt.numObs) > 0
    covar = np.asarray(filt.covar)[:, :36].reshape(-1, 6, 6)
    return {"t_s": t[started].tolist(), "sigma_true": np.asarray(truth.sigma_BN)[started].tolist(),
            "sigma_est": np.asarray(estimate.sigma_BN)[started].tolist(),
            "P_sigma": covar[started, :3, :3].tolist(),
            "omega_true": np.asarray(truth.omega_BN_B)[started].tolist(),
            "omega_est": np.asarray(estimate.omega_BN_B)[started].tolist(),
            "orbit_t_s": (np.asarray(orbit.times()) * macros.NANO2SEC).tolist(), "r_m": np.asarray(orbit.r_BN_N).tolist()}


def main(source, target):
    with open(source) as stream:
        inputs = json.load(stream)
    start = time.perf_counter()
    sim, recorders, kept = build(inputs)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(inputs["duration_s"]))
    middle = time.perf_counter()
    sim.ExecuteSimulation()
    wall = time.perf_counter() - middle
    result = outputs(recorders)
    result.update({"bsk_version": BSK_VERSION, "gravity": "point mass + J2", "wall_s": wall,
                   "setup_s": middle - start, "note": NOTE})
    with open(target, "w") as stream:
        json.dump(result, stream)
    del kept


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
