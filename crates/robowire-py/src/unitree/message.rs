//! `LowCmd`, `LowState`, `HgLowCmd`, `HgLowState`: Unitree's low-level messages as Python
//! objects with the IDL field names, over their struct images.

use std::sync::{Arc, Mutex};

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use unitree_proto::{CdrEncoding, DecodeError, HgLowCmd, HgLowState, IntoBytes, LowCmd, LowState, Message};

use super::view::{Image, StructView, lock};
use crate::errors::{Kind, crc_error, error};
use crate::pyjson;

/// The bytes of a `bytes`, `bytearray` or `memoryview` (or anything `bytes()` takes).
pub(crate) fn bytes_of(data: &Bound<'_, PyAny>) -> PyResult<Vec<u8>> {
    if let Ok(bytes) = data.cast::<PyBytes>() {
        return Ok(bytes.as_bytes().to_vec());
    }
    let builtins = data.py().import("builtins")?;
    Ok(builtins.getattr("bytes")?.call1((data,))?.cast_into::<PyBytes>()?.as_bytes().to_vec())
}

/// A decode error as `DecodeError`, or `CrcError` with both CRCs.
pub(crate) fn raise<M>(name: &str, e: DecodeError<M>) -> PyErr {
    match e {
        DecodeError::CrcMismatch { expected, found, .. } => crc_error(
            format!("{name}: CRC mismatch: the bytes give 0x{expected:08x}, the message carries 0x{found:08x}"),
            expected,
            found,
        ),
        other => error(Kind::Decode, format!("{name}: {}", other.without_message())),
    }
}

fn encoding(name: &str) -> PyResult<CdrEncoding> {
    match name {
        "xcdr1" => Ok(CdrEncoding::Xcdr1),
        "xcdr2" => Ok(CdrEncoding::Xcdr2),
        other => Err(error(Kind::Argument, format!("encoding = {other:?}: \"xcdr1\" or \"xcdr2\""))),
    }
}

/// The message in `image` (its length is `M::IMAGE_LEN` by construction).
pub(crate) fn message_of<M: Message>(image: &Image) -> M {
    M::read_from_bytes(&lock(image)).unwrap_or_default()
}

pub(crate) fn image_of<M: Message>(message: &M) -> Image {
    Arc::new(Mutex::new(message.as_bytes().to_vec()))
}

/// Decodes a struct image (`cdr = false`) or a CDR payload; with `verify`, a wrong CRC or
/// padding raises.
pub(crate) fn decode<M: Message>(data: &[u8], cdr: bool, verify: bool) -> PyResult<M> {
    let unverified =
        if cdr { M::decode_cdr_unverified(data).map(|(u, _)| u) } else { M::decode_image_unverified(data) }
            .map_err(|e| raise(M::DDS_TYPE_NAME, e))?;
    if verify { unverified.verify().map_err(|e| raise(M::DDS_TYPE_NAME, e)) } else { Ok(unverified.message) }
}

/// The sealed image: padding zeroed, CRC written, in the object too (so `msg.crc` is what was
/// sent).
pub(crate) fn seal<M: Message>(image: &Image) -> M {
    let sealed = message_of::<M>(image).sealed();
    lock(image).copy_from_slice(sealed.as_bytes());
    sealed
}

macro_rules! message_class {
    ($(#[$doc:meta])* $class:ident, $msg:ty, $name:literal) => {
        $(#[$doc])*
        #[pyclass(name = $name, module = "robowire.unitree", frozen)]
        pub(crate) struct $class {
            pub(crate) view: StructView,
        }

        impl $class {
            pub(crate) fn from_message(message: &$msg) -> Self {
                Self::from_image(image_of(message))
            }

            fn from_image(image: Image) -> Self {
                Self { view: StructView::message::<$msg>(image, $name) }
            }

            pub(crate) fn message(&self) -> $msg {
                message_of::<$msg>(&self.view.image)
            }
        }

        #[pymethods]
        impl $class {
            /// Struct image length, bytes.
            #[classattr]
            const IMAGE_LEN: usize = <$msg as Message>::IMAGE_LEN;
            /// DDS type name.
            #[classattr]
            const DDS_TYPE_NAME: &'static str = <$msg as Message>::DDS_TYPE_NAME;
            /// DDS topic.
            #[classattr]
            const TOPIC: &'static str = <$msg as Message>::TOPIC;

            /// The message's safe default (for `LowCmd`: head FE EF, level_flag 0xFF, every motor
            /// in servo mode holding nothing: q = PosStopF, dq = VelStopF, kp = kd = 0; states and
            /// the HG messages: all zero), then the given IDL fields
            /// (`LowCmd(level_flag=0xFF, gpio=1)`). `zeroed()` gives the IDL's all-zero default.
            #[new]
            #[pyo3(signature = (**fields))]
            fn new(fields: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
                let this = Self::from_message(&<$msg>::default());
                if let Some(fields) = fields {
                    for (name, value) in fields.iter() {
                        this.view.set_field(&name.extract::<String>()?, &value)?;
                    }
                }
                Ok(this)
            }

            /// Every field zero (the IDL's default, Unitree's `unitree_go_msg_dds__LowCmd_()`).
            #[staticmethod]
            fn zeroed() -> Self {
                Self::from_message(&<$msg as unitree_proto::FromZeros>::new_zeroed())
            }

            fn __getattr__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
                self.view.get_field(py, name)
            }

            fn __setattr__(&self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
                self.view.set_field(name, value)
            }

            fn __dir__(&self) -> Vec<&'static str> {
                <$msg as Message>::FIELDS
                    .idl_fields()
                    .map(|f| f.name)
                    .chain(["encode", "encode_cdr", "decode", "decode_cdr", "to_dict", "from_dict", "computed_crc", "copy", "zeroed"])
                    .collect()
            }

            /// The struct image as the robot's firmware reads it: padding zeroed, CRC written
            /// (into this object too).
            fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
                PyBytes::new(py, seal::<$msg>(&self.view.image).as_bytes())
            }

            fn __bytes__<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
                self.encode(py)
            }

            /// The DDS payload (encapsulation header and CDR body) in `"xcdr1"` (what Unitree's
            /// SDKs publish) or `"xcdr2"`, with the CRC written.
            #[pyo3(signature = (encoding = "xcdr1"))]
            fn encode_cdr<'py>(&self, py: Python<'py>, encoding: &str) -> PyResult<Bound<'py, PyBytes>> {
                let encoding = self::encoding(encoding)?;
                let message = seal::<$msg>(&self.view.image);
                let mut out = vec![0u8; <$msg>::cdr_len(encoding)];
                message.encode_cdr(encoding, &mut out).map_err(|e| error(Kind::Error, e))?;
                Ok(PyBytes::new(py, &out))
            }

            /// From its struct image. Raises `DecodeError` (wrong length, padding) or
            /// `CrcError` (with `expected` and `found`); `verify=False` decodes anyway.
            #[staticmethod]
            #[pyo3(signature = (data, *, verify = true))]
            fn decode(data: &Bound<'_, PyAny>, verify: bool) -> PyResult<Self> {
                Ok(Self::from_message(&decode::<$msg>(&bytes_of(data)?, false, verify)?))
            }

            /// From a DDS payload (XCDR1 or XCDR2, told by its header); errors as `decode`.
            #[staticmethod]
            #[pyo3(signature = (data, *, verify = true))]
            fn decode_cdr(data: &Bound<'_, PyAny>, verify: bool) -> PyResult<Self> {
                Ok(Self::from_message(&decode::<$msg>(&bytes_of(data)?, true, verify)?))
            }

            /// The message as `robowire decode … --json` prints it (IDL names, nested dicts,
            /// shortest floats, non-finite floats as `"NaN"`/`"Infinity"` strings).
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                pyjson::to_py(py, &self.message())
            }

            /// From `to_dict()`'s shape (what `robowire encode` reads): every field present;
            /// `crc` ignored and written. Raises `ArgumentError` naming what is wrong.
            #[staticmethod]
            fn from_dict(fields: &Bound<'_, PyAny>) -> PyResult<Self> {
                let message: $msg = pyjson::from_py(<$msg as Message>::DDS_TYPE_NAME, fields)?;
                Ok(Self::from_message(&message))
            }

            /// The CRC of the zero-padded image (what `encode()` writes).
            fn computed_crc(&self) -> u32 {
                self.message().computed_crc()
            }

            /// An independent copy.
            fn copy(&self) -> Self {
                Self::from_message(&self.message())
            }

            fn __copy__(&self) -> Self {
                self.copy()
            }

            #[pyo3(signature = (_memo))]
            fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
                self.copy()
            }

            fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
                other.cast::<Self>().is_ok_and(|o| o.get().message().as_bytes() == self.message().as_bytes())
            }

            fn __repr__(&self) -> String {
                let m = self.message();
                format!(
                    "<{} {} bytes, crc 0x{:08x} ({})>",
                    $name,
                    <$msg as Message>::IMAGE_LEN,
                    m.crc(),
                    if m.crc() == m.computed_crc() { "ok" } else { "not sealed" }
                )
            }
        }
    };
}

message_class! {
    /// Go2 `unitree_go::msg::dds_::LowCmd_` (812-byte image, topic `rt/lowcmd`).
    PyLowCmd, LowCmd, "LowCmd"
}
message_class! {
    /// Go2 `unitree_go::msg::dds_::LowState_` (1180-byte image, topic `rt/lowstate`).
    PyLowState, LowState, "LowState"
}
message_class! {
    /// HG (G1, H1-2) `unitree_hg::msg::dds_::LowCmd_` (1004-byte image).
    PyHgLowCmd, HgLowCmd, "HgLowCmd"
}
message_class! {
    /// HG (G1, H1-2) `unitree_hg::msg::dds_::LowState_` (2092-byte image).
    PyHgLowState, HgLowState, "HgLowState"
}
