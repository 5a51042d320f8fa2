//! A Python pickle read as data, never run: the stream's opcodes build a [`Value`] tree in which
//! a class or function the pickle names is only its name ([`Value::Global`]) and a call to it
//! only a record of the call ([`Value::Object`]). What those names mean is for the caller to
//! decide ([`crate::neurotac`] accepts numpy's array reconstruction and nothing else), so a
//! malicious pickle cannot execute anything here.
//!
//! Written by hand because no Rust crate reads numpy's object arrays: `serde-pickle` refuses
//! (or blanks, with `replace_unresolved_globals`) every global, and numpy arrays are nothing but
//! globals (`numpy.core.multiarray._reconstruct`, `numpy.dtype`) called with arguments and then
//! given their state (`BUILD`). Protocols 0 to 5 are read, except the opcodes that need a
//! Python runtime to mean anything (persistent ids, the extension registry, `INST`/`OBJ`
//! class instantiation from protocol 0): those are errors naming the opcode and its offset.
//!
//! Bounded: every length is checked against the bytes left before anything is allocated, the
//! memo is a map (an index in the stream cannot make a huge table), and containers are shared
//! (`Rc`), as Python shares them, so a stream of `n` bytes builds at most `O(n)` values; walking
//! a tree that refers to itself is the caller's to bound. A pickle can make a list contain
//! itself, which shared `Rc`s would never free: every mutable container the stream creates is
//! registered, and emptied when the [`Pickle`] (or a failed read) is dropped, which breaks
//! every cycle (one found by fuzzing: a list appended to itself through the memo).

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

/// A list, shared as Python shares it (the memo and every reference see its later appends).
pub type List = Rc<RefCell<Vec<Value>>>;

/// One Python value as the pickle describes it.
#[derive(Debug, Clone)]
pub enum Value {
    /// `None`.
    None,
    /// `True` or `False`.
    Bool(bool),
    /// An integer that fits 64 bits (larger ones are an error).
    Int(i64),
    /// A float.
    Float(f64),
    /// A `str`.
    Str(Rc<str>),
    /// `bytes` or a `bytearray`.
    Bytes(Rc<[u8]>),
    /// A list.
    List(List),
    /// A tuple.
    Tuple(Rc<[Value]>),
    /// A dict, as its (key, value) pairs in order.
    Dict(Rc<RefCell<Vec<(Value, Value)>>>),
    /// A class or function named by the pickle (`module`, `name`), not looked up.
    Global(Rc<str>, Rc<str>),
    /// The result of calling `callable` with `args` (`REDUCE`, `NEWOBJ`), with the state a
    /// later `BUILD` gave it.
    Object(Rc<RefCell<Object>>),
}

/// Every mutable container a stream created (only those can close a cycle: a tuple holds values
/// made before it), emptied on drop so that reference cycles free.
#[derive(Default)]
struct Registry(Vec<Value>);

impl Drop for Registry {
    fn drop(&mut self) {
        for container in &self.0 {
            match container {
                Value::List(l) => l.borrow_mut().clear(),
                Value::Dict(d) => d.borrow_mut().clear(),
                Value::Object(o) => {
                    let mut o = o.borrow_mut();
                    o.args = Value::None;
                    o.state = None;
                }
                _ => {}
            }
        }
    }
}

/// A pickle read: its value, valid while this lives (dropping it frees every container the
/// stream made, cycles included).
pub struct Pickle {
    /// The pickled value.
    pub value: Value,
    _containers: Registry,
}

impl std::fmt::Debug for Pickle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pickle")
            .field("value", &self.value.describe())
            .finish_non_exhaustive()
    }
}

/// A call recorded by [`Value::Object`].
#[derive(Debug, Clone)]
pub struct Object {
    /// What was called (a [`Value::Global`] in every pickle numpy writes).
    pub callable: Value,
    /// Its arguments (a tuple).
    pub args: Value,
    /// The state `BUILD` set, if any.
    pub state: Option<Value>,
}

impl Value {
    /// `module.name` for a [`Value::Global`].
    pub fn global_name(&self) -> Option<String> {
        match self {
            Value::Global(m, n) => Some(format!("{m}.{n}")),
            _ => None,
        }
    }

    /// A short description for error messages (`a list`, `a float`, `numpy.dtype(...)`).
    pub fn describe(&self) -> String {
        match self {
            Value::None => "None".into(),
            Value::Bool(_) => "a bool".into(),
            Value::Int(_) => "an int".into(),
            Value::Float(_) => "a float".into(),
            Value::Str(_) => "a str".into(),
            Value::Bytes(_) => "bytes".into(),
            Value::List(l) => format!("a list of {}", l.borrow().len()),
            Value::Tuple(t) => format!("a tuple of {}", t.len()),
            Value::Dict(_) => "a dict".into(),
            Value::Global(m, n) => format!("the global {m}.{n}"),
            Value::Object(o) => match o.borrow().callable.global_name() {
                Some(name) => format!("a call to {name}"),
                None => "a call".into(),
            },
        }
    }
}

/// Why a pickle could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PickleError {
    /// The stream ends inside an opcode or before `STOP`.
    #[error("the pickle ends at byte offset {offset} before its STOP opcode (truncated?)")]
    Truncated {
        /// Where the stream ended.
        offset: usize,
    },
    /// An opcode this reader does not take.
    #[error("unsupported pickle opcode 0x{opcode:02x} at byte offset {offset}: {why}")]
    Unsupported {
        /// The opcode byte.
        opcode: u8,
        /// Where it is.
        offset: usize,
        /// Why it is refused.
        why: &'static str,
    },
    /// The opcodes do not fit together (a pop from an empty stack, an append to a non-list).
    #[error("malformed pickle at byte offset {offset}: {what}")]
    Malformed {
        /// Where.
        offset: usize,
        /// What is wrong.
        what: String,
    },
}

/// The deepest `MARK` nesting and stack this reader keeps (far beyond any array's pickle).
const MAX_STACK: usize = 1 << 20;

struct Machine<'a> {
    data: &'a [u8],
    pos: usize,
    stack: Vec<Value>,
    marks: Vec<usize>,
    memo: HashMap<u32, Value>,
    containers: Registry,
}

/// Reads one pickle from the start of `data`; returns it and the offset just past its `STOP`
/// opcode.
pub fn read(data: &[u8]) -> Result<(Pickle, usize), PickleError> {
    let mut m = Machine {
        data,
        pos: 0,
        stack: Vec::new(),
        marks: Vec::new(),
        memo: HashMap::new(),
        containers: Registry::default(),
    };
    loop {
        let at = m.pos;
        let op = m.byte()?;
        if let Some(value) = m.step(op, at)? {
            let pickle = Pickle {
                value,
                _containers: std::mem::take(&mut m.containers),
            };
            return Ok((pickle, m.pos));
        }
        if m.stack.len() > MAX_STACK || m.marks.len() > MAX_STACK {
            return Err(m.malformed(at, "the stack grows past a million entries".into()));
        }
    }
}

impl Machine<'_> {
    fn malformed(&self, offset: usize, what: String) -> PickleError {
        PickleError::Malformed { offset, what }
    }

    fn take(&mut self, n: usize) -> Result<&[u8], PickleError> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.data.len())
            .ok_or(PickleError::Truncated {
                offset: self.data.len(),
            })?;
        let bytes = &self.data[self.pos..end];
        self.pos = end;
        Ok(bytes)
    }

    fn byte(&mut self) -> Result<u8, PickleError> {
        Ok(self.take(1)?[0])
    }

    fn le<const N: usize>(&mut self) -> Result<[u8; N], PickleError> {
        let mut out = [0; N];
        out.copy_from_slice(self.take(N)?);
        Ok(out)
    }

    /// A length field of `N` bytes, checked against the bytes left.
    fn len<const N: usize>(&mut self) -> Result<usize, PickleError> {
        let mut raw = [0u8; 8];
        raw[..N].copy_from_slice(&self.le::<N>()?);
        let n = u64::from_le_bytes(raw);
        match usize::try_from(n) {
            Ok(n) if n <= self.data.len() - self.pos => Ok(n),
            _ => Err(PickleError::Truncated {
                offset: self.data.len(),
            }),
        }
    }

    /// A protocol-0 text argument: the bytes up to the next newline.
    fn line(&mut self) -> Result<&str, PickleError> {
        let rest = &self.data[self.pos..];
        let end = rest
            .iter()
            .position(|&b| b == b'\n')
            .ok_or(PickleError::Truncated {
                offset: self.data.len(),
            })?;
        let at = self.pos;
        self.pos += end + 1;
        std::str::from_utf8(&rest[..end])
            .map_err(|_| self.malformed(at, "a text argument is not UTF-8".into()))
    }

    fn pop(&mut self, at: usize) -> Result<Value, PickleError> {
        let floor = self.marks.last().copied().unwrap_or(0);
        if self.stack.len() <= floor {
            return Err(self.malformed(at, "pop from an empty stack".into()));
        }
        self.stack
            .pop()
            .ok_or_else(|| self.malformed(at, "pop from an empty stack".into()))
    }

    fn top(&self, at: usize) -> Result<&Value, PickleError> {
        self.stack
            .last()
            .ok_or_else(|| self.malformed(at, "the stack is empty".into()))
    }

    /// The values pushed since the last `MARK`, and the mark dropped.
    fn pop_mark(&mut self, at: usize) -> Result<Vec<Value>, PickleError> {
        let mark = self
            .marks
            .pop()
            .ok_or_else(|| self.malformed(at, "no MARK to pop to".into()))?;
        Ok(self.stack.split_off(mark.min(self.stack.len())))
    }

    fn push_str(&mut self, n: usize, at: usize) -> Result<(), PickleError> {
        let bytes = self.take(n)?;
        let text = std::str::from_utf8(bytes)
            .map_err(|_| PickleError::Malformed {
                offset: at,
                what: "a str is not UTF-8".into(),
            })?
            .into();
        self.stack.push(Value::Str(text));
        Ok(())
    }

    fn push_bytes(&mut self, n: usize) -> Result<(), PickleError> {
        let bytes: Rc<[u8]> = self.take(n)?.into();
        self.stack.push(Value::Bytes(bytes));
        Ok(())
    }

    fn memo_put(&mut self, key: u32, at: usize) -> Result<(), PickleError> {
        let v = self.top(at)?.clone();
        self.memo.insert(key, v);
        Ok(())
    }

    fn memo_get(&mut self, key: u32, at: usize) -> Result<(), PickleError> {
        let v = self
            .memo
            .get(&key)
            .cloned()
            .ok_or_else(|| self.malformed(at, format!("memo entry {key} was never stored")))?;
        self.stack.push(v);
        Ok(())
    }

    fn append(&mut self, items: Vec<Value>, at: usize) -> Result<(), PickleError> {
        match self.top(at)? {
            Value::List(list) => {
                list.borrow_mut().extend(items);
                Ok(())
            }
            other => Err(self.malformed(at, format!("append to {}", other.describe()))),
        }
    }

    fn set_items(&mut self, items: Vec<Value>, at: usize) -> Result<(), PickleError> {
        if !items.len().is_multiple_of(2) {
            return Err(self.malformed(at, "a dict item without its value".into()));
        }
        match self.top(at)? {
            Value::Dict(dict) => {
                let mut dict = dict.borrow_mut();
                let mut it = items.into_iter();
                while let (Some(k), Some(v)) = (it.next(), it.next()) {
                    dict.push((k, v));
                }
                Ok(())
            }
            other => Err(self.malformed(at, format!("set items of {}", other.describe()))),
        }
    }

    fn call(&mut self, at: usize) -> Result<(), PickleError> {
        let args = self.pop(at)?;
        let callable = self.pop(at)?;
        self.push_container(Value::Object(Rc::new(RefCell::new(Object {
            callable,
            args,
            state: None,
        }))));
        Ok(())
    }

    /// Pushes a new mutable container, registered to be emptied on drop.
    fn push_container(&mut self, container: Value) {
        self.containers.0.push(container.clone());
        self.stack.push(container);
    }

    fn int_text(&mut self, at: usize) -> Result<(), PickleError> {
        let text = self.line()?.trim().trim_end_matches('L').to_string();
        let v = match text.as_str() {
            "00" => Value::Bool(false),
            "01" => Value::Bool(true),
            t => Value::Int(
                t.parse()
                    .map_err(|_| self.malformed(at, format!("`{t}` is not a 64-bit int")))?,
            ),
        };
        self.stack.push(v);
        Ok(())
    }

    /// Runs the opcode `op` found at `at`; `Some` at `STOP`.
    fn step(&mut self, op: u8, at: usize) -> Result<Option<Value>, PickleError> {
        let unsupported = |why| PickleError::Unsupported {
            opcode: op,
            offset: at,
            why,
        };
        match op {
            0x80 => {
                let protocol = self.byte()?;
                if protocol > 5 {
                    return Err(unsupported("a protocol above 5"));
                }
            }
            0x95 => {
                self.le::<8>()?; // FRAME: a length hint only.
            }
            b'.' => return Ok(Some(self.pop(at)?)),
            b'(' => self.marks.push(self.stack.len()),
            b'0' => {
                self.pop(at)?;
            }
            b'1' => {
                self.pop_mark(at)?;
            }
            b'2' => {
                let v = self.top(at)?.clone();
                self.stack.push(v);
            }
            b'N' => self.stack.push(Value::None),
            0x88 => self.stack.push(Value::Bool(true)),
            0x89 => self.stack.push(Value::Bool(false)),
            b'J' => {
                let v = i32::from_le_bytes(self.le()?);
                self.stack.push(Value::Int(v.into()));
            }
            b'K' => {
                let v = self.byte()?;
                self.stack.push(Value::Int(v.into()));
            }
            b'M' => {
                let v = u16::from_le_bytes(self.le()?);
                self.stack.push(Value::Int(v.into()));
            }
            0x8a => {
                let n = usize::from(self.byte()?);
                if n > 8 {
                    return Err(unsupported("an int wider than 64 bits"));
                }
                let bytes = self.take(n)?;
                let negative = bytes.last().is_some_and(|b| b & 0x80 != 0);
                let mut raw = [if negative { 0xff } else { 0 }; 8];
                raw[..n].copy_from_slice(bytes);
                self.stack.push(Value::Int(i64::from_le_bytes(raw)));
            }
            0x8b => return Err(unsupported("an int wider than 64 bits (LONG4)")),
            b'I' => self.int_text(at)?,
            b'L' => self.int_text(at)?,
            b'G' => {
                let v = f64::from_be_bytes(self.le()?);
                self.stack.push(Value::Float(v));
            }
            b'F' => {
                let text = self.line()?.trim().to_string();
                let v = text
                    .parse()
                    .map_err(|_| self.malformed(at, format!("`{text}` is not a float")))?;
                self.stack.push(Value::Float(v));
            }
            0x8c => {
                let n = usize::from(self.byte()?);
                self.push_str(n, at)?;
            }
            b'X' => {
                let n = self.len::<4>()?;
                self.push_str(n, at)?;
            }
            0x8d => {
                let n = self.len::<8>()?;
                self.push_str(n, at)?;
            }
            b'V' => {
                let text: Rc<str> = self.line()?.into();
                self.stack.push(Value::Str(text));
            }
            b'U' | b'C' => {
                let n = usize::from(self.byte()?);
                self.push_bytes(n)?;
            }
            b'T' | b'B' => {
                let n = self.len::<4>()?;
                self.push_bytes(n)?;
            }
            0x8e | 0x96 => {
                let n = self.len::<8>()?;
                self.push_bytes(n)?;
            }
            0x97 | 0x98 => return Err(unsupported("out-of-band buffers")),
            b']' => self.push_container(Value::List(Rc::default())),
            b')' => self.stack.push(Value::Tuple(Rc::from(Vec::new()))),
            b'}' => self.push_container(Value::Dict(Rc::default())),
            b'l' => {
                let items = self.pop_mark(at)?;
                self.push_container(Value::List(Rc::new(RefCell::new(items))));
            }
            b't' => {
                let items = self.pop_mark(at)?;
                self.stack.push(Value::Tuple(items.into()));
            }
            b'd' => {
                let items = self.pop_mark(at)?;
                self.push_container(Value::Dict(Rc::default()));
                self.set_items(items, at)?;
            }
            0x85..=0x87 => {
                let n = usize::from(op - 0x84);
                let mut items = Vec::with_capacity(n);
                for _ in 0..n {
                    items.push(self.pop(at)?);
                }
                items.reverse();
                self.stack.push(Value::Tuple(items.into()));
            }
            b'a' => {
                let v = self.pop(at)?;
                self.append(vec![v], at)?;
            }
            b'e' => {
                let items = self.pop_mark(at)?;
                self.append(items, at)?;
            }
            b's' => {
                let v = self.pop(at)?;
                let k = self.pop(at)?;
                self.set_items(vec![k, v], at)?;
            }
            b'u' => {
                let items = self.pop_mark(at)?;
                self.set_items(items, at)?;
            }
            0x90 => return Err(unsupported("sets")),
            0x91 => return Err(unsupported("frozensets")),
            b'c' => {
                let module: Rc<str> = self.line()?.into();
                let name: Rc<str> = self.line()?.into();
                self.stack.push(Value::Global(module, name));
            }
            0x93 => {
                let name = self.pop(at)?;
                let module = self.pop(at)?;
                match (module, name) {
                    (Value::Str(m), Value::Str(n)) => self.stack.push(Value::Global(m, n)),
                    _ => return Err(self.malformed(at, "STACK_GLOBAL of non-strings".into())),
                }
            }
            b'R' | 0x81 => self.call(at)?,
            0x92 => {
                self.pop(at)?; // NEWOBJ_EX's keyword arguments: kept out, as NEWOBJ has none.
                self.call(at)?;
            }
            b'b' => {
                let state = self.pop(at)?;
                match self.top(at)? {
                    Value::Object(o) => o.borrow_mut().state = Some(state),
                    other => {
                        return Err(self.malformed(at, format!("BUILD on {}", other.describe())));
                    }
                }
            }
            0x94 => {
                let key = u32::try_from(self.memo.len())
                    .map_err(|_| self.malformed(at, "the memo is full".into()))?;
                self.memo_put(key, at)?;
            }
            b'q' => {
                let key = self.byte()?;
                self.memo_put(key.into(), at)?;
            }
            b'r' => {
                let key = u32::from_le_bytes(self.le()?);
                self.memo_put(key, at)?;
            }
            b'p' => {
                let key = self.line()?.trim().to_string();
                let key = key
                    .parse()
                    .map_err(|_| self.malformed(at, format!("memo key `{key}`")))?;
                self.memo_put(key, at)?;
            }
            b'h' => {
                let key = self.byte()?;
                self.memo_get(key.into(), at)?;
            }
            b'j' => {
                let key = u32::from_le_bytes(self.le()?);
                self.memo_get(key, at)?;
            }
            b'g' => {
                let key = self.line()?.trim().to_string();
                let key = key
                    .parse()
                    .map_err(|_| self.malformed(at, format!("memo key `{key}`")))?;
                self.memo_get(key, at)?;
            }
            b'P' | b'Q' => return Err(unsupported("persistent ids need the writer's runtime")),
            0x82..=0x84 => return Err(unsupported("the extension registry")),
            b'i' | b'o' => return Err(unsupported("protocol 0 class instantiation")),
            b'S' => return Err(unsupported("protocol 0 quoted strings")),
            _ => return Err(unsupported("not a pickle opcode")),
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_list_that_contains_itself_is_freed() {
        // EMPTY_LIST, BINPUT 0, BINGET 0, APPEND, STOP: `l = []; l.append(l)`.
        let (pickle, _) = read(&[b']', b'q', 0, b'h', 0, b'a', b'.']).expect("reads");
        let Value::List(list) = &pickle.value else {
            panic!("a list")
        };
        let weak = Rc::downgrade(list);
        assert!(Rc::ptr_eq(
            list,
            match &list.borrow()[0] {
                Value::List(inner) => inner,
                _ => panic!("itself"),
            }
        ));
        drop(pickle);
        assert!(weak.upgrade().is_none(), "the cycle kept the list alive");
    }

    #[test]
    fn a_list_of_floats_and_a_memoized_reference() {
        // pickle.dumps([1.5, [], 2], protocol=2) with the inner list referenced twice by hand:
        // PROTO 2, EMPTY_LIST, BINPUT 0, MARK, BINFLOAT 1.5, EMPTY_LIST, BINPUT 1, BININT1 2,
        // BINGET 1, APPENDS, STOP.
        let mut p = vec![0x80, 2, b']', b'q', 0, b'(', b'G'];
        p.extend_from_slice(&1.5f64.to_be_bytes());
        p.extend_from_slice(&[b']', b'q', 1, b'K', 2, b'h', 1, b'e', b'.']);
        let (pickle, end) = read(&p).expect("reads");
        assert_eq!(end, p.len());
        let Value::List(list) = &pickle.value else {
            panic!("a list")
        };
        let list = list.borrow();
        assert_eq!(list.len(), 4);
        assert!(matches!(list[0], Value::Float(f) if f == 1.5));
        assert!(matches!(list[2], Value::Int(2)));
        match (&list[1], &list[3]) {
            (Value::List(a), Value::List(b)) => assert!(Rc::ptr_eq(a, b)),
            _ => panic!("two references to one list"),
        }
    }

    #[test]
    fn bad_streams_are_errors_with_offsets() {
        let truncated = [
            0x80, 4, 0x95, 1, 0, 0, 0, 0, 0, 0, 0, b'X', 200, 0, 0, 0, b'a',
        ];
        assert!(matches!(
            read(&truncated),
            Err(PickleError::Truncated { .. })
        ));
        assert!(matches!(
            read(&[0x80, 2]),
            Err(PickleError::Truncated { .. })
        ));
        let err = read(b"P1\n.").expect_err("persistent id");
        assert!(err.to_string().contains("at byte offset 0"), "{err}");
        let err = read(b"a.").expect_err("append to nothing");
        assert!(
            matches!(err, PickleError::Malformed { offset: 0, .. }),
            "{err}"
        );
        let err = read(&[b'h', 7, b'.']).expect_err("unknown memo");
        assert!(err.to_string().contains("memo entry 7"), "{err}");
    }

    #[test]
    fn a_global_is_a_name_not_a_call() {
        // `os.system('echo')` in protocol 0: read as a recorded call, never made.
        let (pickle, _) = read(b"cos\nsystem\n(VEcho\ntR.").expect("reads as data");
        let Value::Object(o) = &pickle.value else {
            panic!("a recorded call")
        };
        assert_eq!(
            o.borrow().callable.global_name().as_deref(),
            Some("os.system")
        );
    }
}
