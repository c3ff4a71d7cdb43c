//! Tiny ONNX models that tests make themselves (protobuf through tract's own ONNX types), for
//! the tests of this crate and of the apps above it (feature `test-support`). Not public API.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};

use prost::Message;
use tract_onnx::pb;

/// A float tensor's type of `dims`.
fn value(name: &str, dims: &[i64]) -> pb::ValueInfoProto {
    let dim = dims
        .iter()
        .map(|&d| pb::tensor_shape_proto::Dimension {
            value: Some(pb::tensor_shape_proto::dimension::Value::DimValue(d)),
            ..Default::default()
        })
        .collect();
    pb::ValueInfoProto {
        name: name.into(),
        r#type: Some(pb::TypeProto {
            value: Some(pb::type_proto::Value::TensorType(pb::type_proto::Tensor {
                elem_type: pb::tensor_proto::DataType::Float as i32,
                shape: Some(pb::TensorShapeProto { dim }),
            })),
            ..Default::default()
        }),
        ..Default::default()
    }
}

/// A node `op(inputs) -> outputs`.
fn node(op: &str, inputs: &[&str], outputs: &[&str]) -> pb::NodeProto {
    pb::NodeProto {
        op_type: op.into(),
        name: outputs[0].into(),
        input: inputs.iter().map(|s| (*s).into()).collect(),
        output: outputs.iter().map(|s| (*s).into()).collect(),
        ..Default::default()
    }
}

/// A model: its inputs, a constant weight `w` of `dims`, nodes (operator, inputs, outputs), outputs.
#[derive(Debug, Clone)]
pub struct Model {
    /// Each input's name and shape.
    pub inputs: Vec<(&'static str, Vec<i64>)>,
    /// The constant `w`: its shape and values.
    pub weight: (Vec<i64>, Vec<f32>),
    /// Each node: its operator, inputs and outputs.
    pub nodes: Vec<(&'static str, Vec<&'static str>, Vec<&'static str>)>,
    /// Each output's name and shape.
    pub outputs: Vec<(&'static str, Vec<i64>)>,
}

impl Model {
    /// Written to a file of its own; its path.
    pub fn write(&self) -> PathBuf {
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let graph = pb::GraphProto {
            name: "tiny".into(),
            node: self.nodes.iter().map(|(op, i, o)| node(op, i, o)).collect(),
            initializer: vec![pb::TensorProto {
                name: "w".into(),
                dims: self.weight.0.clone(),
                data_type: pb::tensor_proto::DataType::Float as i32,
                float_data: self.weight.1.clone(),
                ..Default::default()
            }],
            input: self.inputs.iter().map(|(n, d)| value(n, d)).collect(),
            output: self.outputs.iter().map(|(n, d)| value(n, d)).collect(),
            ..Default::default()
        };
        let model = pb::ModelProto {
            ir_version: 8,
            opset_import: vec![pb::OperatorSetIdProto { domain: String::new(), version: 17 }],
            graph: Some(graph),
            ..Default::default()
        };
        let path = std::env::temp_dir().join(format!(
            "robowire-policy-{}-{}.onnx",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::write(&path, model.encode_to_vec()).expect("writing a model to the temporary directory");
        path
    }
}

/// actions [1, 2] = obs [1, 3] · w [3, 2]: no state.
pub fn linear(w: [f32; 6]) -> Model {
    matmul(3, 2, w.to_vec())
}

/// actions [1, `actions`] = obs [1, `obs`] · w, `w` row-major [`obs`, `actions`].
pub fn matmul(obs: i64, actions: i64, w: Vec<f32>) -> Model {
    Model {
        inputs: vec![("obs", vec![1, obs])],
        weight: (vec![obs, actions], w),
        nodes: vec![("MatMul", vec!["obs", "w"], vec!["actions"])],
        outputs: vec![("actions", vec![1, actions])],
    }
}

/// actions = obs · w + h_in, h_out = actions: the actions add up over the steps.
pub fn summing(w: [f32; 6]) -> Model {
    Model {
        inputs: vec![("obs", vec![1, 3]), ("h_in", vec![1, 2])],
        weight: (vec![3, 2], w.to_vec()),
        nodes: vec![
            ("MatMul", vec!["obs", "w"], vec!["a"]),
            ("Add", vec!["a", "h_in"], vec!["actions"]),
            ("Identity", vec!["actions"], vec!["h_out"]),
        ],
        outputs: vec![("actions", vec![1, 2]), ("h_out", vec![1, 2])],
    }
}
