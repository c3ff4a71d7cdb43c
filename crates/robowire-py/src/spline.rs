//! `robowire.spline`: the ZSL-1's joint interface on POSIX shared memory (`/spline_shm`,
//! `/imu_shm`), over the `zsl` facade's spline client and IMU reader.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use zsl::{ImuReader, JointControl, JointIndex, Leg, SplineClient, SplineCommandBlock, SplineError};

use crate::errors::{Kind, chain, error};
use crate::owned::{Owned, closeable};
use crate::record::{Capture, record_arg};
use crate::runtime::{self, seconds};
use crate::sim::state_dict;
use crate::stats::dict;

fn raise(e: SplineError) -> PyErr {
    let kind = match &e {
        SplineError::NonFinite { .. } => Kind::Argument,
        SplineError::DaemonNotRunning { .. } | SplineError::DaemonStalled { .. } => Kind::NoState,
        SplineError::Timeout { .. } => Kind::Timeout,
        _ => Kind::Error,
    };
    error(kind, chain(&e))
}

/// Sixteen values `[leg][joint]` (legs FR, FL, RR, RL; joints abad, hip, knee, foot) from one
/// number, 16 numbers, or 4 rows of 4.
fn sixteen(name: &str, value: Option<&Bound<'_, PyAny>>) -> PyResult<[[f32; 4]; 4]> {
    let Some(value) = value else { return Ok([[0.0; 4]; 4]) };
    if let Ok(v) = value.extract::<f64>() {
        return Ok([[v as f32; 4]; 4]);
    }
    let mut flat = Vec::with_capacity(16);
    for item in value.try_iter()? {
        let item = item?;
        match item.extract::<f64>() {
            Ok(v) => flat.push(v),
            Err(_) => {
                for v in item.try_iter()? {
                    flat.push(v?.extract::<f64>()?);
                }
            }
        }
    }
    if flat.len() != 16 {
        return Err(error(
            Kind::Argument,
            format!("{name}: one number, 16, or 4 rows of 4 ([leg][joint]); {} values given", flat.len()),
        ));
    }
    Ok(std::array::from_fn(|leg| std::array::from_fn(|joint| flat[4 * leg + joint] as f32)))
}

/// The vendor daemon's joint interface: write all sixteen joints' PD targets, read the state it
/// publishes every millisecond.
///
/// ```python
/// with robowire.sim.Spline() as daemon:
///     joints = robowire.spline.SplineClient(daemon.spline_name)
///     joints.write_command(p_des=[0.0, 0.72, -1.45, 0.0] * 4, kp=30.0, kd=1.0)
///     state = joints.wait_state(timeout_s=0.1)
/// ```
#[pyclass(name = "SplineClient", module = "robowire.spline", frozen)]
pub(crate) struct PySplineClient {
    client: Owned<SplineClient>,
    capture: Capture,
}

#[pymethods]
impl PySplineClient {
    /// Opens the spline object `name`. Raises `NoStateError` if no daemon created it.
    /// `stall_after_s`: how long without fresh state while waiting makes the daemon stalled
    /// (`None`: the facade's 10 ms, the daemon's period being 1 ms). `record`: a path or a
    /// `robowire.Recorder` to record the commands written and the states read into
    /// (`spline/spline`).
    #[new]
    #[pyo3(signature = (name = "/spline_shm", *, stall_after_s = None, record = None))]
    fn new(name: &str, stall_after_s: Option<f64>, record: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let stall_after = runtime::timeout("stall_after_s", stall_after_s)?;
        let client = SplineClient::open(name).map_err(raise)?;
        let client = match stall_after {
            Some(bound) => client.with_stall_after(bound),
            None => client,
        };
        let (links, capture) = record_arg(record, "robowire.spline.SplineClient")?;
        let client = match links {
            Some(r) => client.with_tap(r.link(robowire_devices::SPLINE_LINK, &zsl_proto::description::SPLINE_CLIENT)),
            None => client,
        };
        Ok(Self { client: Owned::new("spline client", client), capture })
    }

    /// Writes every joint's target and raises the control flag. Each argument is one number
    /// (every joint), 16, or 4 rows of 4 (`[leg][joint]`): position `p_des` rad, velocity
    /// `v_des` rad/s, gains `kp`, `kd`, feed-forward torque `t_ff` N·m. NaN or infinities raise
    /// `ArgumentError` and nothing is written.
    #[pyo3(signature = (p_des, *, v_des = None, kp = None, kd = None, t_ff = None))]
    fn write_command(
        &self,
        p_des: &Bound<'_, PyAny>,
        v_des: Option<&Bound<'_, PyAny>>,
        kp: Option<&Bound<'_, PyAny>>,
        kd: Option<&Bound<'_, PyAny>>,
        t_ff: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let [p, v, kp, kd, t] = [
            sixteen("p_des", Some(p_des))?,
            sixteen("v_des", v_des)?,
            sixteen("kp", kp)?,
            sixteen("kd", kd)?,
            sixteen("t_ff", t_ff)?,
        ];
        let mut block = SplineCommandBlock::default();
        for leg in Leg::ALL {
            for joint in JointIndex::ALL {
                let (l, j) = (leg.index(), joint as usize);
                *block.joint_mut(leg, joint) = JointControl::new(p[l][j], v[l][j], kp[l][j], kd[l][j], t[l][j]);
            }
        }
        self.client.with(|c| c.write_command(&block))?.map_err(raise)
    }

    /// The state the daemon published since the last read, or `None`.
    fn try_read_state<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let state = self.client.with(|c| c.try_read_state())?.map_err(raise)?;
        state.map(|s| state_dict(py, &s)).transpose()
    }

    /// Waits up to `timeout_s` for fresh state: `{"p_rad", "v_radps", "t_nm", "flags"}`, each
    /// `[leg][joint]`. Raises `TimeoutError`, or `NoStateError` when the daemon stalled.
    #[pyo3(signature = (timeout_s = 0.1))]
    fn wait_state<'py>(&self, py: Python<'py>, timeout_s: f64) -> PyResult<Bound<'py, PyDict>> {
        let timeout = seconds("timeout_s", timeout_s)?;
        let outcome =
            runtime::wait_sliced(py, Some(timeout), |slice| match self.client.with(|c| c.wait_state(slice)) {
                Ok(Err(SplineError::Timeout { .. })) => None,
                other => Some(other),
            })?;
        match outcome {
            Some(result) => state_dict(py, &result?.map_err(raise)?),
            None => Err(error(Kind::Timeout, format!("no fresh spline state within {timeout_s} s"))),
        }
    }

    /// No fresh state for longer than the stall bound (`stall_after_s`) while polling.
    #[getter]
    fn is_stalled(&self) -> PyResult<bool> {
        self.client.with(|c| c.is_stalled())
    }

    /// Commands written, states read, stalls.
    fn counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.client.with(|c| c.counters())?;
        Ok(
            dict!(py, { "commands_written" => c.commands_written, "states_read" => c.states_read, "stalls" => c.stalls }),
        )
    }
}

closeable!(PySplineClient, client, capture, "Unmaps the object, then finishes its own capture. Idempotent.");

/// The IMU samples the daemon publishes on `/imu_shm`.
#[pyclass(name = "ImuReader", module = "robowire.spline", frozen)]
pub(crate) struct PyImuReader {
    reader: Owned<ImuReader>,
    capture: Capture,
}

#[pymethods]
impl PyImuReader {
    /// Opens the IMU object `name`. `record`: a path or a `robowire.Recorder` to record each
    /// sample read into (`spline/imu`).
    #[new]
    #[pyo3(signature = (name = "/imu_shm", *, record = None))]
    fn new(name: &str, record: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let reader = ImuReader::open(name).map_err(|e| error(Kind::NoState, chain(&e)))?;
        let (links, capture) = record_arg(record, "robowire.spline.ImuReader")?;
        let reader = match links {
            Some(r) => reader.with_tap(r.link(robowire_devices::SPLINE_IMU_LINK, &zsl_proto::description::IMU)),
            None => reader,
        };
        Ok(Self { reader: Owned::new("IMU reader", reader), capture })
    }

    /// The latest consistent sample: `timestamp_ns`, `acc_mps2`, `gyro_radps`,
    /// `quaternion_wxyz`. Raises `NoStateError` if none was published yet.
    fn read<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.reader.with(|r| r.read())?.map_err(|e| error(Kind::NoState, chain(&e)))?;
        Ok(dict!(py, {
            "timestamp_ns" => s.timestamp_ns,
            "acc_mps2" => s.acc_mps2.to_vec(),
            "gyro_radps" => s.gyro_radps.to_vec(),
            "quaternion_wxyz" => s.quaternion_wxyz.to_vec(),
        }))
    }
}

closeable!(PyImuReader, reader, capture, "Unmaps the object, then finishes its own capture. Idempotent.");

/// Adds the classes to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SplineClient", m.py().get_type::<PySplineClient>())?;
    m.add("ImuReader", m.py().get_type::<PyImuReader>())?;
    Ok(())
}
