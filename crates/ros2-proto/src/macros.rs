/// A ROS 2 struct: the Rust struct with its fields in IDL order, and its [`CdrValue`]
/// implementation writing and reading them in that order.
///
/// [`CdrValue`]: crate::CdrValue
macro_rules! ros_struct {
    ($(#[$meta:meta])* pub struct $name:ident { $($(#[$fmeta:meta])* pub $field:ident: $ty:ty,)* }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty,)*
        }

        impl $crate::CdrValue for $name {
            const MIN_LEN: usize = 0 $(+ <$ty as $crate::CdrValue>::MIN_LEN)*;
            #[allow(unused_variables)]
            fn write(&self, w: &mut robowire_core::cdr::CdrWriter<'_>) {
                $($crate::CdrValue::write(&self.$field, w);)*
            }
            #[allow(unused_variables)]
            fn read(
                r: &mut robowire_core::cdr::CdrReader<'_>,
                _field: &'static str,
            ) -> Result<Self, robowire_core::cdr::CdrError> {
                Ok(Self { $($field: <$ty as $crate::CdrValue>::read(r, concat!(stringify!($name), ".", stringify!($field)))?,)* })
            }
        }
    };
}

/// A top-level message: a [`CdrType`](robowire_core::cdr::CdrType) under its DDS type name,
/// XCDR1 only.
macro_rules! ros_message {
    ($($name:ty => $type_name:literal;)*) => {$(
        impl robowire_core::cdr::CdrType for $name {
            const TYPE_NAME: &'static str = $type_name;
            type Error = robowire_core::cdr::CdrError;

            fn body_len(&self) -> usize {
                let mut w = robowire_core::cdr::CdrWriter::measure(robowire_core::cdr::CdrEncoding::Xcdr1);
                $crate::CdrValue::write(self, &mut w);
                w.position()
            }

            fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
                let mut w = robowire_core::cdr::CdrWriter::new(robowire_core::cdr::CdrEncoding::Xcdr1, out);
                $crate::CdrValue::write(self, &mut w);
                w.finish()
            }

            fn decode_body(
                encoding: robowire_core::cdr::CdrEncoding,
                body: &[u8],
            ) -> Result<Self, robowire_core::cdr::CdrError> {
                if encoding != robowire_core::cdr::CdrEncoding::Xcdr1 {
                    return Err(robowire_core::cdr::CdrError::Encoding(encoding));
                }
                let mut r = robowire_core::cdr::CdrReader::new(encoding, body);
                let message = <Self as $crate::CdrValue>::read(&mut r, $type_name)?;
                r.finish()?;
                Ok(message)
            }
        }
    )*};
}
