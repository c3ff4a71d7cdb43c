//! The Unitree messages as OMG IDL text, for recorders: an MCAP channel with message encoding
//! `cdr` and a schema with encoding `omgidl`, whose name is [`IdlSchema::name`] (the type's
//! globally scoped name, `unitree_go::msg::dds_::LowState_`, which is also its DDS type name)
//! and whose data is [`IdlSchema::text`]: one self-contained IDL source, every nested struct
//! defined in it, no preprocessor directives (MCAP's format registry, `omgidl`).
//!
//! Every struct is `@final`, as Unitree's IDL declares them: the vendor publishes XCDR1
//! (`00 01`), and in XCDR2 (`00 07`, PLAIN_CDR2) a final struct has no DHEADER or member
//! headers of its own. Field order, types and array lengths are those of Unitree's IDL and of
//! this crate's codecs ([`crate::go2`], [`crate::hg`], [`crate::sport_state`], [`crate::api`]).
//!
//! ```
//! use unitree_proto::idl::{self, schema_of_type};
//! use unitree_proto::{LowState, Message};
//!
//! let schema = schema_of_type(LowState::DDS_TYPE_NAME).unwrap();
//! assert_eq!(schema.name, "unitree_go::msg::dds_::LowState_");
//! assert!(schema.text.contains("struct MotorState_"));
//! assert!(schema_of_type("unitree_go::msg::dds_::Nothing_").is_none());
//! # let _ = idl::GO2_LOW_CMD;
//! ```

/// An `omgidl` schema: the top-level type's scoped name and the IDL text that defines it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IdlSchema {
    /// The top-level type's globally scoped name (`a::b::C`): MCAP's schema name, and the DDS
    /// type name.
    pub name: &'static str,
    /// Self-contained OMG IDL defining the type and every type it uses.
    pub text: &'static str,
}

/// `unitree_go` structs shared by more than one message.
macro_rules! go2_imu_state {
    () => {
        "      @final
      struct IMUState_ {
        float quaternion[4];
        float gyroscope[3];
        float accelerometer[3];
        float rpy[3];
        octet temperature;
      };
"
    };
}

/// The three nested modules around `$body`.
macro_rules! modules {
    ($module:literal, $($body:expr),+ $(,)?) => {
        concat!("module ", $module, " {\n  module msg {\n    module dds_ {\n", $($body,)+ "    };\n  };\n};\n")
    };
}

/// `unitree_go::msg::dds_::LowCmd_` (Go2), with `MotorCmd_` and `BmsCmd_`.
pub const GO2_LOW_CMD: IdlSchema = IdlSchema {
    name: "unitree_go::msg::dds_::LowCmd_",
    text: modules!(
        "unitree_go",
        "      @final
      struct MotorCmd_ {
        octet mode;
        float q;
        float dq;
        float tau;
        float kp;
        float kd;
        unsigned long reserve[3];
      };
      @final
      struct BmsCmd_ {
        octet off;
        octet reserve[3];
      };
      @final
      struct LowCmd_ {
        octet head[2];
        octet level_flag;
        octet frame_reserve;
        unsigned long sn[2];
        unsigned long version[2];
        unsigned short bandwidth;
        MotorCmd_ motor_cmd[20];
        BmsCmd_ bms_cmd;
        octet wireless_remote[40];
        octet led[12];
        octet fan[2];
        octet gpio;
        unsigned long reserve;
        unsigned long crc;
      };
"
    ),
};

/// `unitree_go::msg::dds_::LowState_` (Go2), with `IMUState_`, `MotorState_` and `BmsState_`.
pub const GO2_LOW_STATE: IdlSchema = IdlSchema {
    name: "unitree_go::msg::dds_::LowState_",
    text: modules!(
        "unitree_go",
        go2_imu_state!(),
        "      @final
      struct MotorState_ {
        octet mode;
        float q;
        float dq;
        float ddq;
        float tau_est;
        float q_raw;
        float dq_raw;
        float ddq_raw;
        octet temperature;
        unsigned long lost;
        unsigned long reserve[2];
      };
      @final
      struct BmsState_ {
        octet version_high;
        octet version_low;
        octet status;
        octet soc;
        long current;
        unsigned short cycle;
        octet bq_ntc[2];
        octet mcu_ntc[2];
        unsigned short cell_vol[15];
      };
      @final
      struct LowState_ {
        octet head[2];
        octet level_flag;
        octet frame_reserve;
        unsigned long sn[2];
        unsigned long version[2];
        unsigned short bandwidth;
        IMUState_ imu_state;
        MotorState_ motor_state[20];
        BmsState_ bms_state;
        short foot_force[4];
        short foot_force_est[4];
        unsigned long tick;
        octet wireless_remote[40];
        octet bit_flag;
        float adc_reel;
        octet temperature_ntc1;
        octet temperature_ntc2;
        float power_v;
        float power_a;
        unsigned short fan_frequency[4];
        unsigned long reserve;
        unsigned long crc;
      };
"
    ),
};

/// `unitree_go::msg::dds_::SportModeState_` (Go2 `rt/sportmodestate`), with `TimeSpec_`,
/// `IMUState_` and `PathPoint_`; its codec is [`crate::sport_state::SportModeState`].
pub const GO2_SPORT_MODE_STATE: IdlSchema = IdlSchema {
    name: "unitree_go::msg::dds_::SportModeState_",
    text: modules!(
        "unitree_go",
        "      @final
      struct TimeSpec_ {
        long sec;
        unsigned long nanosec;
      };
",
        go2_imu_state!(),
        "      @final
      struct PathPoint_ {
        float t_from_start;
        float x;
        float y;
        float yaw;
        float vx;
        float vy;
        float vyaw;
      };
      @final
      struct SportModeState_ {
        TimeSpec_ stamp;
        unsigned long error_code;
        IMUState_ imu_state;
        octet mode;
        float progress;
        octet gait_type;
        float foot_raise_height;
        float position[3];
        float body_height;
        float velocity[3];
        float yaw_speed;
        float range_obstacle[4];
        short foot_force[4];
        float foot_position_body[12];
        float foot_speed_body[12];
        PathPoint_ path_point[10];
      };
"
    ),
};

/// `unitree_hg::msg::dds_::LowCmd_` (G1, H1-2), with `MotorCmd_`.
pub const HG_LOW_CMD: IdlSchema = IdlSchema {
    name: "unitree_hg::msg::dds_::LowCmd_",
    text: modules!(
        "unitree_hg",
        "      @final
      struct MotorCmd_ {
        octet mode;
        float q;
        float dq;
        float tau;
        float kp;
        float kd;
        unsigned long reserve;
      };
      @final
      struct LowCmd_ {
        octet mode_pr;
        octet mode_machine;
        MotorCmd_ motor_cmd[35];
        unsigned long reserve[4];
        unsigned long crc;
      };
"
    ),
};

/// `unitree_hg::msg::dds_::LowState_` (G1, H1-2), with `IMUState_` and `MotorState_`.
pub const HG_LOW_STATE: IdlSchema = IdlSchema {
    name: "unitree_hg::msg::dds_::LowState_",
    text: modules!(
        "unitree_hg",
        "      @final
      struct IMUState_ {
        float quaternion[4];
        float gyroscope[3];
        float accelerometer[3];
        float rpy[3];
        short temperature;
      };
      @final
      struct MotorState_ {
        octet mode;
        float q;
        float dq;
        float ddq;
        float tau_est;
        short temperature[2];
        float vol;
        unsigned long sensor[2];
        unsigned long motorstate;
        unsigned long reserve[4];
      };
      @final
      struct LowState_ {
        unsigned long version[2];
        octet mode_pr;
        octet mode_machine;
        unsigned long tick;
        IMUState_ imu_state;
        MotorState_ motor_state[35];
        octet wireless_remote[40];
        unsigned long reserve[4];
        unsigned long crc;
      };
"
    ),
};

/// `RequestIdentity_`, shared by both service messages.
macro_rules! api_identity {
    () => {
        "      @final
      struct RequestIdentity_ {
        long long id;
        long long api_id;
      };
"
    };
}

/// `unitree_api::msg::dds_::Request_`, with its header's structs.
pub const API_REQUEST: IdlSchema = IdlSchema {
    name: "unitree_api::msg::dds_::Request_",
    text: modules!(
        "unitree_api",
        api_identity!(),
        "      @final
      struct RequestLease_ {
        long long id;
      };
      @final
      struct RequestPolicy_ {
        long priority;
        boolean noreply;
      };
      @final
      struct RequestHeader_ {
        RequestIdentity_ identity;
        RequestLease_ lease;
        RequestPolicy_ policy;
      };
      @final
      struct Request_ {
        RequestHeader_ header;
        string parameter;
        sequence<octet> binary;
      };
"
    ),
};

/// `unitree_api::msg::dds_::Response_`, with its header's structs.
pub const API_RESPONSE: IdlSchema = IdlSchema {
    name: "unitree_api::msg::dds_::Response_",
    text: modules!(
        "unitree_api",
        api_identity!(),
        "      @final
      struct ResponseStatus_ {
        long code;
      };
      @final
      struct ResponseHeader_ {
        RequestIdentity_ identity;
        ResponseStatus_ status;
      };
      @final
      struct Response_ {
        ResponseHeader_ header;
        string data;
        sequence<octet> binary;
      };
"
    ),
};

/// Every schema of this module.
pub static SCHEMAS: [&IdlSchema; 7] =
    [&GO2_LOW_CMD, &GO2_LOW_STATE, &GO2_SPORT_MODE_STATE, &HG_LOW_CMD, &HG_LOW_STATE, &API_REQUEST, &API_RESPONSE];

/// The schema of the DDS type `dds_type_name` (`unitree_hg::msg::dds_::LowCmd_`); `None` for a
/// type this module does not describe.
pub fn schema_of_type(dds_type_name: &str) -> Option<&'static IdlSchema> {
    SCHEMAS.iter().copied().find(|s| s.name == dds_type_name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::{REQUEST_TYPE_NAME, RESPONSE_TYPE_NAME};
    use crate::sport_state::SportModeState;
    use crate::{HgLowCmd, HgLowState, LowCmd, LowState, Message};

    #[test]
    fn every_dds_type_of_the_crate_has_its_schema() {
        let types = [
            (LowCmd::DDS_TYPE_NAME, &GO2_LOW_CMD),
            (LowState::DDS_TYPE_NAME, &GO2_LOW_STATE),
            (HgLowCmd::DDS_TYPE_NAME, &HG_LOW_CMD),
            (HgLowState::DDS_TYPE_NAME, &HG_LOW_STATE),
            (SportModeState::DDS_TYPE_NAME, &GO2_SPORT_MODE_STATE),
            (REQUEST_TYPE_NAME, &API_REQUEST),
            (RESPONSE_TYPE_NAME, &API_RESPONSE),
        ];
        for (name, schema) in types {
            assert_eq!(schema_of_type(name), Some(schema), "{name}");
        }
        assert_eq!(schema_of_type("unitree_go.msg.dds_.LowCmd_"), None);
    }

    #[test]
    fn the_top_level_struct_is_defined_last_in_its_modules() {
        for schema in SCHEMAS {
            let mut path = schema.name.split("::");
            let module = path.next().unwrap();
            let ty = path.nth(2).unwrap();
            assert!(schema.text.starts_with(&*format!("module {module} {{\n  module msg {{\n    module dds_ {{\n")));
            let last = schema.text.rfind("struct ").unwrap();
            assert!(schema.text[last..].starts_with(&*format!("struct {ty} {{")), "{}", schema.name);
            assert!(!schema.text.contains('#'), "{}", schema.name);
        }
    }
}
