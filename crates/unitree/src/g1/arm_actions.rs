//! [`ArmActions`]: the G1's arm action service (service `arm`, Unitree's `G1ArmActionClient`,
//! `unitree_proto::api::g1_arm`), with its documented refusals typed.

use crate::UnitreeError;
use crate::services::ServiceHandle;
use unitree_proto::api::g1_arm::{self, error};

use crate::g1::G1Error;

/// The G1's arm action service (service `arm`, Unitree's `G1ArmActionClient`,
/// `unitree_proto::api::g1_arm`), its documented refusals typed. Every call: any executor, the
/// low-level options' service timeout.
#[derive(Debug, Clone)]
pub struct ArmActions {
    service: ServiceHandle,
}

impl ArmActions {
    pub(crate) fn new(service: ServiceHandle) -> Self {
        Self { service }
    }

    /// ExecuteAction `action` (Unitree's ids: 99 release the arms, 11 two-hand kiss, 15 hands
    /// up, 17 clap, 18 high five, 19 hug, 20 heart, 26 high wave, 27 shake hand, …). The request
    /// carries the id under both keys the SDKs use, `{"data": id, "action_id": id}` (the Python
    /// SDK sends `data`, the C++ SDK `action_id`). Refusals: [`G1Error::ArmSdkOccupied`],
    /// [`G1Error::ArmHolding`], [`G1Error::InvalidActionId`], [`G1Error::ArmFsm`].
    pub async fn execute_action(&self, action: i64) -> Result<(), G1Error> {
        let parameter = format!(r#"{{"data":{action},"action_id":{action}}}"#);
        self.service.call(g1_arm::EXECUTE_ACTION, parameter).await.map(drop).map_err(|e| match e {
            UnitreeError::Refused { code: error::ARM_SDK_OCCUPIED, .. } => G1Error::ArmSdkOccupied { action },
            UnitreeError::Refused { code: error::HOLDING, .. } => G1Error::ArmHolding { action },
            UnitreeError::Refused { code: error::INVALID_ACTION_ID, .. } => G1Error::InvalidActionId { action },
            UnitreeError::Refused { code: error::INVALID_FSM_ID, .. } => G1Error::ArmFsm { action },
            e => G1Error::from(e),
        })
    }

    /// Action 99: the arms let go of a held action.
    pub async fn release_arm(&self) -> Result<(), G1Error> {
        self.execute_action(g1_arm::RELEASE_ARM).await
    }

    /// GetActionList: the answer's data as the robot sends it (JSON).
    pub async fn action_list(&self) -> Result<String, G1Error> {
        Ok(self.service.call(g1_arm::GET_ACTION_LIST, "{}").await?.data)
    }
}
